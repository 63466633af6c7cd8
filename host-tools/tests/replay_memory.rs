//! `bowl replay` streams: a capture far larger than its memory use replays in a fixed amount of
//! memory (its own test binary, so the children's peak memory is the replay's alone).

mod common;

use common::{bowl, last_json, stdout, temp_dir};

#[test]
fn a_large_capture_replays_in_constant_memory() {
    let dir = temp_dir("replay-memory");
    let one = dir.join("one.bin");
    let made = bowl(&[
        "serve",
        "--capture",
        one.to_str().unwrap(),
        "--seconds",
        "600",
        "--command",
        "0:speed,1800,2100",
        "--command",
        "0:start",
    ]);
    assert!(made.status.success(), "{}", stdout(&made));
    let piece = std::fs::read(&one).unwrap();
    // About 2.5 MB per 600 s; 40 copies make a capture of about 100 MB.
    let big = dir.join("big.bin");
    {
        use std::io::Write;
        let mut f = std::io::BufWriter::new(std::fs::File::create(&big).unwrap());
        for _ in 0..40 {
            f.write_all(&piece).unwrap();
        }
    }
    let size_mb = std::fs::metadata(&big).unwrap().len() as f64 / 1e6;
    assert!(size_mb > 80.0, "{size_mb} MB");
    let csv = dir.join("big.csv");
    let out = bowl(&[
        "replay",
        big.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stdout(&out));
    let s = last_json(&out);
    assert_eq!(s["telemetry_frames"].as_u64(), Some(40 * 30_000), "{s}");
    // Peak resident memory of the children (the serve and the replay), kB on Linux.
    let usage =
        nix::sys::resource::getrusage(nix::sys::resource::UsageWho::RUSAGE_CHILDREN).unwrap();
    let peak_mb = usage.max_rss() as f64 / 1024.0;
    assert!(
        peak_mb < 0.25 * size_mb,
        "replaying {size_mb:.0} MB peaked at {peak_mb:.1} MB of memory"
    );
    let _ = std::fs::remove_dir_all(dir);
}
