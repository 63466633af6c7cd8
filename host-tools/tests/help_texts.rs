//! The help texts as a new user reads them: every example `bowl send --help` and `bowl serve
//! --help` show runs as written on a virtual rig, the numbers in them have their units, and
//! every help text (each subcommand's, recursively) names one concept one way. Before:
//! `speed 1800 2100` and `0:speed,1800,2100` gave no unit (mrad/s), `--batch` sent the user to
//! "the module docs" for its columns, `--rig-file` took `<RIG.toml>` in three commands and
//! `<RIG_FILE>` in seven, `chart settling --quick` sent the user to
//! `control::Extent::Quick`, `--line-noise-percent` stated its default twice, and the precession
//! and spin speeds were omega1/omega2 in `kinematics` but w1/w2 in `predict`.

mod common;

use common::{Sim, bowl, capture_timed, send, stdout, temp_dir};

fn help(path: &[&str]) -> String {
    let mut args = path.to_vec();
    args.push("--help");
    let out = bowl(&args);
    assert!(out.status.success(), "bowl {args:?}");
    stdout(&out)
}

/// The `code` spans of a text.
fn spans(text: &str) -> Vec<&str> {
    text.split('`').skip(1).step_by(2).collect()
}

/// Every help text: `bowl --help` and each subcommand's, recursively, with its path.
fn every_help() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut todo: Vec<Vec<String>> = vec![vec![]];
    while let Some(path) = todo.pop() {
        let refs: Vec<&str> = path.iter().map(String::as_str).collect();
        let text = help(&refs);
        let mut listing = false;
        for line in text.lines() {
            if line.starts_with("Commands:") {
                listing = true;
            } else if line.trim().is_empty() {
                listing = false;
            } else if listing {
                let name = line.split_whitespace().next().unwrap();
                if name != "help" {
                    let mut sub = path.clone();
                    sub.push(name.to_string());
                    todo.push(sub);
                }
            }
        }
        out.push((format!("bowl {}", path.join(" ")), text));
    }
    out
}

#[test]
fn every_example_of_bowl_send_runs_on_a_virtual_rig() {
    let text = help(&["send"]);
    let examples = text
        .split("e.g.")
        .nth(1)
        .unwrap()
        .split("(see docs")
        .next()
        .unwrap();
    let commands = spans(examples);
    assert!(commands.len() >= 10, "{commands:?}");
    let sim = Sim::start(&[]);
    for c in &commands {
        let (code, out) = send(&sim.path, c);
        // `clear` is refused while the rig has no fault: the rig's own rule, said in words.
        let fine = code == 0 || (code == 1 && out.contains("STATE"));
        assert!(fine, "bowl send PORT {c}: exit {code}: {out}");
    }
    for (example, unit) in [("speed 1800 2100`", "mrad/s"), ("rtime cori 2500`", "ms)")] {
        let after = text.split(example).nth(1).unwrap();
        assert!(
            after.trim_start().starts_with('(') && after[..40].contains(unit),
            "{text}"
        );
    }
}

#[test]
fn every_timed_command_example_of_bowl_serve_runs() {
    let text = help(&["serve"]);
    let examples: Vec<&str> = spans(&text)
        .into_iter()
        .filter(|s| {
            s.split_once(':')
                .is_some_and(|(at, _)| at.parse::<u32>().is_ok())
        })
        .collect();
    assert!(examples.len() >= 3, "{examples:?}");
    let dir = temp_dir("help-serve-examples");
    let capture = capture_timed(&dir, "6", &examples);
    let replay = bowl(&["replay", capture.to_str().unwrap()]);
    assert!(replay.status.success(), "{}", stdout(&replay));
    let flag = text.split("--command").nth(1).unwrap();
    assert!(
        flag.contains("AT_MS: the device time") && flag.contains("mrad/s"),
        "{text}"
    );
}

#[test]
fn every_help_text_names_one_thing_one_way() {
    let all = every_help();
    assert!(all.len() > 30, "{} help texts", all.len());
    for (cmd, text) in &all {
        for word in [
            "module docs",
            "Option<",
            "Vec<",
            "PathBuf",
            "Some(",
            "<RIG_FILE>",
        ] {
            assert!(!text.contains(word), "{cmd} --help shows `{word}`:\n{text}");
        }
        // A Rust path to a type or variant (`control::Extent::Quick`); the QEMU log's test
        // names (`cost::` benchmarks) are what the user finds in that log, so they may stay.
        for (i, _) in text.match_indices("::") {
            let next = text[i + 2..].chars().next().unwrap_or(' ');
            assert!(
                !next.is_uppercase(),
                "{cmd} --help names a Rust type:\n{text}"
            );
        }
        for word in [" w1 ", " w2 "] {
            assert!(
                !text.contains(word),
                "{cmd} --help: omega1/omega2 elsewhere:\n{text}"
            );
        }
        // A default stated in the sentence and again by clap: "(...; default 0) [default: 0]".
        for (i, _) in text.match_indices("[default: ") {
            let value = text[i + 10..].split(']').next().unwrap();
            let before = &text[..i];
            let said = format!("default {value})");
            assert!(
                !before.trim_end().ends_with(&said),
                "{cmd}: twice [default: {value}]"
            );
        }
    }
    let predict = help(&["predict"]);
    for column in ["`model`", "`w_rad_s`", "`mu`", "`ri_m`", "`R_m`"] {
        assert!(
            predict.contains(column),
            "--batch names {column}: {predict}"
        );
    }
}

/// `--step-s` said "default: 0.01 / omega" for every model, but the rolling model's rk4 steps
/// 0.001 s and the bowl model's 0.0001 s (at 1.8 rad/s, 0.01 / omega is 0.0056 s). The step
/// the help states for each is the one a run without `--step-s` takes.
#[test]
fn the_step_predict_help_states_is_the_step_it_takes() {
    let text = help(&["predict"]);
    let flag = text.split("--step-s <").nth(1).unwrap();
    for (model, stated, other) in [("rolling", "0.001", "0.0001"), ("bowl", "0.0001", "0.001")] {
        let says = format!("the {model} model's {stated} s");
        let says_rk4 = format!("the {model} model's rk4 {stated} s");
        assert!(
            flag.contains(&says) || flag.contains(&says_rk4),
            "{says}: {flag}"
        );
        let release = |step: &[&str]| {
            let mut args = vec!["predict", "--model", model, "--method", "rk4", "--json"];
            args.extend(["--precession-rad-s", "1.8", "--spin-rad-s", "1.8"]);
            args.extend(["--axes-angle-deg", "60", "--release-azimuth-deg", "0"]);
            args.extend(["--speed-range", "false"]);
            args.extend_from_slice(step);
            common::json(&args)["per_release"][0].clone()
        };
        let default = release(&[]);
        assert_eq!(default, release(&["--step-s", stated]), "{model}");
        assert_ne!(
            default,
            release(&["--step-s", other]),
            "{model}: the step matters"
        );
    }
}
