//! `SET NAME VALUE` refused: the parameter's own range, or the rule that ties it to the others.

use model_core::binding::{ParamRole, TABLE_PARAMS, scene_from_params, table_from_params};
use model_core::wire::{Command, ParamId, ParamValues};

/// `set NAME VALUE` refused: not an integer, or outside the parameter's own range (the
/// command table's words), or, if the value is inside it, the rule that ties it to the other
/// parameters (`params`: the rig's, asked right after the refusal).
pub(crate) fn set_range(words: &[String], params: Option<&ParamValues>) -> Option<String> {
    match Command::from_words(words) {
        Err(refusal) => Some(refusal.to_string()),
        Ok(Command::SetParam { id, value }) => Some(format!(
            "{} = {value} {} is inside its own range but not with the other parameters: {}",
            id.token(),
            id.unit(),
            params
                .and_then(|p| conflict(id, value, p))
                .unwrap_or_else(|| {
                    "see them with `bowl send PORT params` (docs/protocol.md says what each \
                     configures)"
                        .into()
                })
        )),
        Ok(_) => None,
    }
}

/// The rule between parameters that `id = value` breaks with the others at `params`: the
/// wire ranges hold every rule of one parameter alone (model-core's binding tests check that),
/// so what is left ties two or more together.
fn conflict(id: ParamId, value: i32, params: &ParamValues) -> Option<String> {
    let mut next = *params;
    next[id.index()] = value;
    let p = |id: ParamId| next[id.index()];
    let (start, rim) = (p(ParamId::StartUm), p(ParamId::RimUm));
    // The rig's own scene check (the start inside the rim is its one rule between the two).
    if matches!(id, ParamId::StartUm | ParamId::RimUm) && scene_from_params::<f64>(&next).is_err() {
        return Some(format!(
            "the granule's start radius {} = {start} um must lie inside the rim {} = {rim} um; \
             set {} below {rim} um, or widen {} first",
            ParamId::StartUm.token(),
            ParamId::RimUm.token(),
            ParamId::StartUm.token(),
            ParamId::RimUm.token()
        ));
    }
    if ParamRole::of(id) == ParamRole::ResidenceTable && table_from_params(&next).is_err() {
        let zero: Vec<&str> = TABLE_PARAMS[2..]
            .iter()
            .filter(|t| p(**t) <= 0)
            .map(|t| t.token())
            .collect();
        return Some(format!(
            "the residence-time table would be on ({} {} above {} {}) with {} at 0; every \
             time must be above 0 while it is on: write the times first and {} last (`bowl \
             predict ... --store-table PORT` does that)",
            ParamId::RtSpeedHiMradS.token(),
            p(ParamId::RtSpeedHiMradS),
            ParamId::RtSpeedLoMradS.token(),
            p(ParamId::RtSpeedLoMradS),
            zero.join(", "),
            ParamId::RtSpeedHiMradS.token()
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::binding::default_params;

    fn w(s: &str) -> Vec<String> {
        s.split_whitespace().map(str::to_string).collect()
    }

    #[test]
    fn set_out_of_range_names_the_range() {
        let (lo, hi) = ParamId::MuPpm.range();
        let text = set_range(&w(&format!("set MU_PPM {}", i64::from(hi) + 1)), None).unwrap();
        assert!(text.contains(&format!("{lo}..={hi}")), "{text}");
        assert!(
            text.starts_with(&format!("MU_PPM {} ppm", i64::from(hi) + 1)),
            "{text}"
        );
    }

    /// The rules that tie parameters together are named with both values; the rig's own
    /// refusal of the same SET (model-core's binding) is the independent check that they are
    /// the rules it applies.
    #[test]
    fn set_refused_with_the_others_names_the_rule_and_both_values() {
        let p = default_params();
        let rim = p[ParamId::RimUm.index()];
        let text = set_range(&w(&format!("set START_UM {rim}")), Some(&p)).unwrap();
        assert!(
            text.contains(&format!(
                "START_UM = {rim} um must lie inside the rim RIM_UM = {rim} um"
            )),
            "{text}"
        );
        let start = p[ParamId::StartUm.index()];
        let text = set_range(&w(&format!("set RIM_UM {start}")), Some(&p)).unwrap();
        assert!(text.contains("widen RIM_UM first"), "{text}");
        assert!(
            model_core::binding::scene_from_params::<f32>(&{
                let mut q = p;
                q[ParamId::RimUm.index()] = start;
                q
            })
            .is_err()
        );
        let text = set_range(&w("set RT_W_HI_MRAD_S 3600"), Some(&p)).unwrap();
        assert!(text.contains("RT_T1_US, RT_T2_US"), "{text}");
        assert!(text.contains("RT_W_HI_MRAD_S last"), "{text}");
        // Without the rig's parameters, it says where to look rather than guessing a rule.
        let text = set_range(&w("set START_UM 5"), None).unwrap();
        assert!(text.contains("bowl send PORT params"), "{text}");
    }
}
