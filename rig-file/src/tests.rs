//! The rig-file parser's tests.

use super::*;

#[test]
fn an_empty_file_is_the_nominal_rig() {
    let r = parse("", "x.toml", "x").unwrap();
    assert_eq!(r.len(), 1);
    assert_eq!(r[0].params, PlantParams::nominal());
    assert_eq!(r[0].seed, 1);
    assert_eq!(r[0].particle, None);
}

fn particle(text: &str) -> Result<ParticleParams> {
    Ok(parse(text, "rig.toml", "rig")?[0].particle.unwrap())
}

#[test]
fn the_particle_table_reads_every_key() {
    let p = particle(
        "[particle]\nmodel = \"flat\"\nmu = 0.03\nmu_spread = 0.001\nk2 = 0.6\n\
         release_radius_m = 0.04\nrim_radius_m = 0.12\nrelease_spread_m = 0.002\n\
         gate_jitter_s = 0.01\n",
    )
    .unwrap();
    assert_eq!(p.model, Model::Flat);
    assert_eq!(
        (p.mu, p.mu_spread, p.k2, p.release_radius_m),
        (0.03, 0.001, 0.6, 0.04)
    );
    assert_eq!(
        (p.rim_radius_m, p.release_spread_m, p.gate_jitter_s),
        (0.12, 0.002, 0.01)
    );
    // Keys left out keep the defaults; the plant keys beside it are read too.
    let r = &parse(
        "supply_v = 10.0\n[particle]\nmu = 0.05\n",
        "rig.toml",
        "rig",
    )
    .unwrap()[0];
    assert_eq!(r.params.supply_v, 10.0);
    let p = r.particle.unwrap();
    assert_eq!((p.mu, p.k2), (0.05, ParticleParams::default().k2));
}

#[test]
fn particle_errors_name_the_line_the_key_and_the_range() {
    let e = particle("\n[particle]\nmu = -1\n").unwrap_err().to_string();
    assert!(
        e.contains("rig.toml, line 3")
            && e.contains("[particle] mu = -1 is outside its range 0 to 1"),
        "{e}"
    );
    let e = particle("[particle]\nmodel = \"round\"\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 2") && e.contains("\"flat\", \"coriolis\" or \"bowl\""),
        "{e}"
    );
    let e = particle("[particle]\nmus = 1\n").unwrap_err().to_string();
    assert!(e.contains("unknown field `mus`"), "{e}");
    let e = particle("[particle]\nk2 = \"a\"\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 2"), "{e}");
    let e = particle("[particle]\nrelease_radius_m = 0.2\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("must lie inside the rim (rim_radius_m = 0.15)"),
        "{e}"
    );
}

#[test]
fn keys_reach_the_plant() {
    let r = parse(
        "supply_v = 10.5\nseed = 7\n[spin]\ninertia_kg_m2 = 0.05\npulses_per_rev = 60\n",
        "x.toml",
        "x",
    )
    .unwrap();
    assert_eq!(r[0].params.supply_v, 10.5);
    assert_eq!(r[0].seed, 7);
    assert_eq!(r[0].params.axes[1].motor.inertia_kg_m2, 0.05);
    assert_eq!(r[0].params.axes[1].sensor.pulses_per_rev, 60);
    assert_eq!(r[0].params.axes[0], PlantParams::nominal().axes[0]);
}

#[test]
fn current_sense_is_off_by_default_and_its_keys_reach_both_axes() {
    let r = parse("", "x.toml", "x").unwrap();
    assert!(!r[0].params.axes[0].current_sense.enabled);
    assert_eq!(r[0].params, PlantParams::nominal());
    let r = parse("current_sense = true\n", "x.toml", "x").unwrap();
    assert_eq!(r[0].params.axes[1].current_sense, CurrentSense::TYPICAL);
    let r = parse(
        "[[plant]]\nname = \"a\"\ncurrent_sense = true\ncurrent_offset_a = -0.05\n\
         current_gain_error = 0.1\ncurrent_noise_a = 0.002\n[[plant]]\nname = \"b\"\n",
        "f.toml",
        "x",
    )
    .unwrap();
    let c = r[0].params.axes[0].current_sense;
    assert!(c.enabled);
    assert_eq!((c.offset_a, c.gain_error, c.noise_a), (-0.05, 0.1, 0.002));
    assert_eq!(r[0].params.axes[1].current_sense, c);
    assert!(!r[1].params.axes[0].current_sense.enabled);
    assert!(
        r[1].clone().with_current_sense().params.axes[0]
            .current_sense
            .enabled
    );
}

#[test]
fn a_current_sense_error_key_needs_current_sense() {
    let e = parse("current_noise_a = 0.01\n", "c.toml", "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("c.toml, line 1"), "{e}");
    assert!(e.contains("current_sense = true"), "{e}");
    let e = parse(
        "current_sense = true\ncurrent_gain_error = 0.9\n",
        "c.toml",
        "x",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("line 2") && e.contains("current_gain_error"),
        "{e}"
    );
}

#[test]
fn a_value_out_of_range_names_file_line_key_and_range() {
    let e = parse(
        "seed = 2\n[precession]\ntooth_error = 0.7\n",
        "bad.toml",
        "x",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("bad.toml"), "{e}");
    assert!(e.contains("line 3"), "{e}");
    assert!(e.contains("[precession] tooth_error"), "{e}");
    assert!(e.contains("0 to 0.45"), "{e}");
}

#[test]
fn an_unknown_key_names_its_line() {
    let e = parse(
        "[[plant]]\nname = \"a\"\n[[plant]]\nname = \"b\"\nsuply_v = 3\n",
        "f.toml",
        "x",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("line 5"), "{e}");
    assert!(e.contains("suply_v"), "{e}");
}

#[test]
fn a_family_needs_names() {
    let e = parse("[[plant]]\nsupply_v = 11\n", "f.toml", "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no name"), "{e}");
    let r = parse(
        "[[plant]]\nname = \"a\"\n[[plant]]\nname = \"b\"\nsupply_v = 11\n",
        "f",
        "x",
    )
    .unwrap();
    assert_eq!(r.len(), 2);
    assert_eq!(r[1].name, "b");
    assert_eq!(r[1].params.supply_v, 11.0);
}

/// A rig wrapped in [[plant]] with its tables left as [precession] (and a key before the
/// first plant): refused with where each goes, not serde's "expected `plant`".
#[test]
fn a_family_says_where_stray_tables_go() {
    let text = "seed = 2\n[[plant]]\nname = \"a\"\n[precession]\nsupply_v = 11\n";
    let e = parse(text, "f.toml", "x").unwrap_err().to_string();
    assert!(
        e.contains("[precession] (write it [plant.precession])"),
        "{e}"
    );
    assert!(
        e.contains("seed (write it after the plant's [[plant]] line)"),
        "{e}"
    );
    let text = "[[plant]]\nname = \"a\"\n[plant.precession]\ncoulomb_nm = 0.2\n";
    assert_eq!(parse(text, "f.toml", "x").unwrap().len(), 1);
}

/// A granule that starts touching the corner is refused in the rig file's own keys, the
/// granule's radius among them (it widens the fillet the centre cannot enter).
#[test]
fn a_start_in_the_corner_names_every_key_that_moves_it() {
    let e = parse(
        "[particle]\nmodel = \"bowl\"\nrelease_radius_m = 0.07\n\
         [bowl]\nrim_radius_m = 0.075\nwall_height_m = 0.01\nfillet_radius_m = 0.0\n\
         particle_radius_m = 0.01\n",
        "x.toml",
        "x",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("release_radius_m = 0.07")
            && e.contains("particle_radius_m = 0.01")
            && e.contains("give a smaller release_radius_m, fillet_radius_m or particle_radius_m"),
        "{e}"
    );
}

/// A rig file edited by hand: a misspelt key or table is named with the name it may have meant
/// (the table as a table, not a "field"); a value typed with its unit, which TOML told to
/// quote ("string values must be quoted") and then refused as a string, is said to be a number
/// with a unit; a decimal comma ("unexpected key or value, expected newline") is said to be
/// one; a fractional seed, taken as its whole part without a word, is refused.
#[test]
fn hand_edits_are_said_in_words() {
    let err = |text: &str| parse(text, "r.toml", "r").err().unwrap().to_string();
    let e = err("[bowl]\nwall_angel_deg = 60.0\n");
    assert!(
        e.starts_with("rig file r.toml, line 2: wall_angel_deg: unknown field `wall_angel_deg`"),
        "{e}"
    );
    assert!(e.ends_with("(did you mean `wall_angle_deg`?)"), "{e}");
    let e = err("seed = 3\r\n\r\n[bowll] # the bowl\r\naxes_angle_deg = 60.0\r\n");
    assert!(
        e.starts_with("rig file r.toml, line 3: unknown table `bowll`"),
        "{e}"
    );
    assert!(e.ends_with("(did you mean `bowl`?)"), "{e}");
    // Nothing near: no guess.
    let e = err("[particle]\nvelocity = 1.0\n");
    assert!(!e.contains("did you mean"), "{e}");
    for (line, value) in [
        ("mu = 0.029 kg   # rolling resistance", "0.029 kg"),
        ("mu = \"0.029 kg\"", "0.029 kg"),
        ("mu = 0.029kg", "0.029kg"),
    ] {
        let e = err(&format!("[particle]\r\n{line}\r\n"));
        assert_eq!(
            e,
            format!(
                "rig file r.toml, line 2: mu: `{value}` is a number with a unit: write the \
                 number alone (mu = 0.029), in the unit the key's name says (SI: m, kg, s, \
                 rad/s, V, ohm, ...)"
            ),
            "{line}"
        );
    }
    let e = err("[bowl]\naxes_angle_deg = 60,5\n");
    assert!(
        e.contains(
            "line 2: axes_angle_deg: `60,5` has a decimal comma: TOML takes a decimal \
                    point (axes_angle_deg = 60.5)"
        ),
        "{e}"
    );
    // A string key whose value starts with digits is no unit mistake.
    let e = err("[particle]\nmodel = \"2 flat\"\n");
    assert!(!e.contains("with a unit"), "{e}");
    let e = err("seed = 3.5\n");
    assert!(
        e.contains("line 1: seed = 3.5 must be a whole number"),
        "{e}"
    );
}
