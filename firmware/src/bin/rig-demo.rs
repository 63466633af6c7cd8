//! The rig demo without hardware: the firmware's application logic on the emulated board (QEMU
//! netduinoplus2) with the simulated plant, driven by `bowl send` through a scripted session,
//! watched live by `bowl monitor`, and summed up at the end (a table and an SVG chart of the
//! speeds). Ends by itself.
//!
//! Run: `cargo run -p firmware --no-default-features --features host-demo --bin rig-demo`
//! Output: `target/rig-demo/` (telemetry.csv from the monitor, speeds.svg, summary.txt).
//! Every time below is the board's own (QEMU `-icount`), read from the telemetry frames. The
//! settling times count from the last frame before the command, so they include the command's
//! transit, which depends on how busy the host is: the closed loop itself is tested exactly by
//! `tests/qemu_rig_e2e.rs`.

use std::fmt::Write as _;
use std::process::{Command, Stdio};

use firmware::host::{self, Board, Splitter};
use model_core::wire::{DeviceState, Residence, Telemetry};

/// One step of the session: a command, then how long to watch (device ms).
struct Step {
    say: &'static str,
    command: &'static [&'static str],
    watch_ms: u32,
}

const SESSION: &[Step] = &[
    Step {
        say: "idle after boot",
        command: &["status"],
        watch_ms: 1_000,
    },
    Step {
        say: "motor speeds 2.0 and 3.0 rad/s",
        command: &["speed", "2000", "3000"],
        watch_ms: 0,
    },
    Step {
        say: "start",
        command: &["start"],
        watch_ms: 7_000,
    },
    Step {
        say: "target residence time 800 ms (Coriolis model)",
        command: &["rtime", "cori", "800"],
        watch_ms: 8_000,
    },
    Step {
        say: "the spin sensor dies",
        command: &["inject", "sensor2"],
        watch_ms: 2_000,
    },
    Step {
        say: "start while faulted (refused)",
        command: &["start"],
        watch_ms: 0,
    },
    Step {
        say: "sensor back",
        command: &["inject", "none"],
        watch_ms: 0,
    },
    Step {
        say: "clear the fault",
        command: &["clear"],
        watch_ms: 1_000,
    },
    Step {
        say: "start again (targets were reset: 1.5 and 1.5 rad/s)",
        command: &["speed", "1500", "1500"],
        watch_ms: 0,
    },
    Step {
        say: "start",
        command: &["start"],
        watch_ms: 6_000,
    },
    Step {
        say: "stop",
        command: &["stop"],
        watch_ms: 8_000,
    },
];

/// What happened in one step, for the summary.
struct Outcome {
    say: &'static str,
    exit: i32,
    from_ms: u32,
    frames: Vec<Telemetry>,
}

fn main() {
    let out_dir = host::workspace_root().join("target/rig-demo");
    std::fs::create_dir_all(&out_dir).expect("output directory");
    let csv = out_dir.join("telemetry.csv");
    let _ = std::fs::remove_file(&csv);

    println!("rig-demo: building the emulated board's image and the bowl command");
    let bowl = host::build_bowl();
    let elf = host::build_image("qemu-rig");
    let total_ms: u32 = SESSION.iter().map(|s| s.watch_ms).sum::<u32>() + 4_000;
    let board = Board::boot_with(&elf, &["-append", &format!("seconds={}", total_ms / 1000)]);
    let split = Splitter::start(board.usart.try_clone().expect("dup"), true);
    let monitor_pty = split.monitor_pty().expect("monitor terminal").to_owned();
    let mut monitor = Command::new(&bowl)
        .arg("monitor")
        .arg(&monitor_pty)
        .arg("--plain")
        .arg("--log")
        .arg(&csv)
        .stdin(Stdio::null())
        .spawn()
        .expect("bowl monitor runs");

    split.wait_device_ms(0, 200);
    let mut outcomes = Vec::new();
    for step in SESSION {
        println!("\n== {}", step.say);
        let from_ms = split.last().time_ms;
        let (exit, _) = split.send(&bowl, step.command);
        let frames = if step.watch_ms > 0 {
            split.wait_device_ms(from_ms, step.watch_ms)
        } else {
            Vec::new()
        };
        outcomes.push(Outcome {
            say: step.say,
            exit,
            from_ms,
            frames,
        });
    }

    let _ = monitor.kill();
    let _ = monitor.wait();
    let (ok, console) = board.finish();
    let all = split.with_seen(|s| s.telemetry.clone());
    let (corrupt, hello) = split.with_seen(|s| (s.corrupt, s.hello));
    let summary = summarize(&outcomes, &all, corrupt, hello, ok, &console);
    println!("\n{summary}");
    std::fs::write(out_dir.join("summary.txt"), &summary).expect("summary written");
    std::fs::write(out_dir.join("speeds.svg"), chart(&all)).expect("chart written");
    println!(
        "rig-demo: wrote {}, {} and {}",
        csv.display(),
        out_dir.join("speeds.svg").display(),
        out_dir.join("summary.txt").display()
    );
    if !ok {
        std::process::exit(1);
    }
}

fn state_name(s: DeviceState) -> &'static str {
    match s {
        DeviceState::Idle => "idle",
        DeviceState::Commissioning => "commissioning",
        DeviceState::SpinningUp => "spinning up",
        DeviceState::Running => "running",
        DeviceState::Stopping => "stopping",
        DeviceState::Faulted => "faulted",
    }
}

fn residence(r: Residence) -> String {
    match r {
        Residence::Ms(ms) => format!("{ms} ms"),
        Residence::NeverLeaves => "never leaves".into(),
        Residence::Unavailable => "-".into(),
    }
}

/// First device time from which `measured` stays within 2 % of `set` (both mrad/s) to the
/// end of `frames`, relative to `from_ms`.
fn settling_ms(frames: &[Telemetry], from_ms: u32, axis: usize) -> Option<u32> {
    let pick = |t: &Telemetry| {
        let m = if axis == 0 { t.precession } else { t.spin };
        (i32::from(m.set_mrad_s), i32::from(m.measured_mrad_s))
    };
    let last_out = frames.iter().rposition(|t| {
        let (set, meas) = pick(t);
        set == 0 || (meas - set).abs() * 50 > set
    });
    match last_out {
        None => frames.first().map(|t| t.time_ms - from_ms),
        Some(i) if i + 1 < frames.len() => Some(frames[i + 1].time_ms - from_ms),
        Some(_) => None,
    }
}

fn summarize(
    outcomes: &[Outcome],
    all: &[Telemetry],
    corrupt: usize,
    hello: usize,
    board_ok: bool,
    console: &[String],
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "rig-demo summary (device time from the telemetry frames)"
    );
    let _ = writeln!(
        s,
        "{:<48} {:>4} {:>9} {:>12} {:>12} {:>13} {:>13}",
        "step", "exit", "t ms", "end state", "w1/w2 mrad/s", "settle1 ms", "settle2 ms"
    );
    for o in outcomes {
        let end = o.frames.last();
        let state = end.map_or("", |t| state_name(t.state));
        let speeds = end.map_or(String::new(), |t| {
            format!(
                "{}/{}",
                t.precession.measured_mrad_s, t.spin.measured_mrad_s
            )
        });
        let settle = |axis| {
            settling_ms(&o.frames, o.from_ms, axis).map_or("-".to_string(), |ms| ms.to_string())
        };
        let _ = writeln!(
            s,
            "{:<48} {:>4} {:>9} {:>12} {:>12} {:>13} {:>13}",
            o.say,
            o.exit,
            o.from_ms,
            state,
            speeds,
            if end.is_some() {
                settle(0)
            } else {
                String::new()
            },
            if end.is_some() {
                settle(1)
            } else {
                String::new()
            },
        );
        if o.say.starts_with("target residence")
            && let Some(t) = end
        {
            {
                let _ = writeln!(
                    s,
                    "    predicted at the measured speeds: flat {}, Coriolis {} (target 800 ms)",
                    residence(t.residence_flat),
                    residence(t.residence_coriolis)
                );
            }
        }
        if o.say.starts_with("the spin sensor")
            && let Some(f) = o.frames.iter().find(|t| t.state == DeviceState::Faulted)
        {
            {
                let _ = writeln!(
                    s,
                    "    fault {:?} {} ms after the command, duties {}/{} bp",
                    f.fault,
                    f.time_ms - o.from_ms,
                    f.precession.duty_bp,
                    f.spin.duty_bp
                );
            }
        }
    }
    let gaps: u32 = all
        .windows(2)
        .map(|w| u32::from(w[1].seq.wrapping_sub(w[0].seq).wrapping_sub(1)))
        .sum();
    let _ = writeln!(
        s,
        "telemetry: {} frames good, {} corrupt, {} missing (sequence gaps); {} hello",
        all.len(),
        corrupt,
        gaps,
        hello
    );
    let truth = host::plant_truth(console);
    if let Some(last) = truth.last() {
        let _ = writeln!(
            s,
            "plant (truth) at {} ms: {:.3} / {:.3} rad/s; board exit {}",
            last.t_ms,
            last.speed_rad_s[0],
            last.speed_rad_s[1],
            if board_ok { "ok" } else { "FAILED" }
        );
    }
    s
}

/// Set and measured speeds of both motors against device time, as an SVG line chart.
fn chart(frames: &[Telemetry]) -> String {
    let (w, h, pad) = (900.0, 420.0, 50.0);
    let t_max = frames
        .last()
        .map_or(1.0, |t| t.time_ms as f64 / 1000.0)
        .max(1.0);
    let v_max = frames
        .iter()
        .flat_map(|t| {
            [
                t.precession.set_mrad_s,
                t.precession.measured_mrad_s,
                t.spin.set_mrad_s,
                t.spin.measured_mrad_s,
            ]
        })
        .map(|v| f64::from(v) / 1000.0)
        .fold(1.0, f64::max)
        * 1.1;
    let x = |t: f64| pad + (w - 2.0 * pad) * t / t_max;
    let y = |v: f64| h - pad - (h - 2.0 * pad) * v / v_max;
    let series = |f: &dyn Fn(&Telemetry) -> i16| {
        frames
            .iter()
            .map(|t| {
                format!(
                    "{:.1},{:.1}",
                    x(t.time_ms as f64 / 1000.0),
                    y(f64::from(f(t)) / 1000.0)
                )
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut svg = format!(
        "<svg xmlns='http://www.w3.org/2000/svg' width='{w}' height='{h}' font-family='sans-serif' font-size='12'>\n\
         <rect width='100%' height='100%' fill='white'/>\n"
    );
    // Faulted intervals shaded, one band per interval.
    let mut start: Option<f64> = None;
    for (i, t) in frames.iter().enumerate() {
        let faulted = t.state == DeviceState::Faulted;
        let t_s = t.time_ms as f64 / 1000.0;
        match (faulted, start) {
            (true, None) => start = Some(t_s),
            (false, Some(s0)) | (true, Some(s0)) if !faulted || i + 1 == frames.len() => {
                let (a, b) = (x(s0), x(t_s));
                let _ = writeln!(
                    svg,
                    "<rect x='{a:.1}' y='{pad}' width='{:.1}' height='{}' fill='#fdd'/>",
                    b - a,
                    h - 2.0 * pad
                );
                start = None;
            }
            _ => {}
        }
    }
    let _ = writeln!(
        svg,
        "<line x1='{pad}' y1='{0}' x2='{1}' y2='{0}' stroke='black'/><line x1='{pad}' y1='{pad}' x2='{pad}' y2='{0}' stroke='black'/>",
        h - pad,
        w - pad
    );
    for k in 0..=5 {
        let v = v_max * f64::from(k) / 5.0;
        let _ = writeln!(svg, "<text x='5' y='{:.1}'>{v:.2}</text>", y(v) + 4.0);
        let t = t_max * f64::from(k) / 5.0;
        let _ = writeln!(
            svg,
            "<text x='{:.1}' y='{}'>{t:.1} s</text>",
            x(t) - 10.0,
            h - pad + 18.0
        );
    }
    type Pick = fn(&Telemetry) -> i16;
    let lines: [(Pick, &str, &str); 4] = [
        (|t| t.precession.set_mrad_s, "#1f77b4", "4 3"),
        (|t| t.precession.measured_mrad_s, "#1f77b4", "none"),
        (|t| t.spin.set_mrad_s, "#d62728", "4 3"),
        (|t| t.spin.measured_mrad_s, "#d62728", "none"),
    ];
    for (pick, colour, dash) in lines {
        let _ = writeln!(
            svg,
            "<polyline fill='none' stroke='{colour}' stroke-dasharray='{dash}' points='{}'/>",
            series(&pick)
        );
    }
    let _ = writeln!(
        svg,
        "<text x='{pad}' y='20'>motor speeds, rad/s, against device time (dashed: set; solid: measured from pulses; red band: faulted)</text>"
    );
    let _ = writeln!(
        svg,
        "<text x='{pad}' y='36' fill='#1f77b4'>precession (omega1)</text><text x='{}' y='36' fill='#d62728'>spin (omega2)</text>",
        pad + 160.0
    );
    svg.push_str("</svg>\n");
    svg
}
