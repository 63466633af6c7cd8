//! One release's entry in a `per_release` list: the same keys for every model of the tilted
//! bowl (docs/model.md §10): `azimuth_deg`, `left`, `residence_time_s` and `regime` (each
//! mode's share of the time; `null` where the model does not follow the modes or gave up). A
//! model adds its own keys after these; the entries were built three ways with three shapes.

use serde_json::{Map, Value, json};

/// The common entry, with `more` keys added.
pub fn entry(azimuth_deg: f64, residence_time_s: Option<f64>, regime: Value, more: Value) -> Value {
    let mut v = json!({
        "azimuth_deg": azimuth_deg, "left": residence_time_s.is_some(),
        "residence_time_s": residence_time_s, "regime": regime,
    });
    if let (Some(obj), Value::Object(more)) = (v.as_object_mut(), more) {
        obj.extend(more);
    }
    v
}

/// No keys of the model's own.
pub fn none() -> Value {
    Value::Object(Map::new())
}
