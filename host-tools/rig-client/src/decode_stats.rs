//! The decoder's counters (frames intact, damaged, missing; bytes skipped, and why) as one JSON
//! object: `bowl replay`'s output, the monitor's and the demo's summaries.

use model_core::wire::DecodeStats;
use serde_json::json;

/// Statistics as one JSON object.
pub fn stats_json(s: &DecodeStats) -> serde_json::Value {
    json!({
        "bytes": s.bytes,
        "frames_ok": s.frames_ok,
        "frames_corrupt": s.frames_corrupt,
        "frames_missing": s.frames_missing,
        "bytes_skipped": s.bytes_skipped,
        "bad_crc": s.bad_crc,
        "malformed": s.malformed,
        "oversize": s.oversize,
        "truncated": s.truncated,
        "duplicates": s.duplicates,
        "reordered": s.reordered,
        "restarts": s.restarts,
    })
}
