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

/// Asked for one release (`--release-azimuth-deg B`), the answer also carries that release's
/// `residence_time_s` at the top (null where it did not leave), beside the mean, min and max a
/// list or `all` gives: the key issue 15 named for one azimuth, which a reader of a single
/// release looks for first.
pub fn add_single_release(v: &mut Value) {
    let Some(obj) = v.as_object_mut() else {
        return;
    };
    let t = match obj.get("per_release").and_then(Value::as_array) {
        Some(per) if per.len() == 1 => per[0]["residence_time_s"].clone(),
        _ => return,
    };
    obj.insert("residence_time_s".into(), t);
}
