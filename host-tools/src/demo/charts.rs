//! The demo's charts, drawn with the shared plot module (`lab::chart::plot`): per motor, the
//! setpoint and the measured speed over device time, the session's steps and the fault marked.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use model_core::wire::{FaultCode, Residence, Telemetry};

use super::script::{Mark, MarkKind};
use lab::chart::plot::{Figure, Mark as Style, PlotError, Scale, Series, VLine};

/// Palette indices (see the plot module).
use lab::chart::log::{self, FAULT_COLOUR};
const STEP_COLOUR: usize = 7;

fn t_s(t: &Telemetry) -> f64 {
    f64::from(t.time_ms) / 1000.0
}

fn markers(marks: &[Mark], tel: &[Telemetry]) -> Vec<VLine> {
    let mut v: Vec<VLine> = marks
        .iter()
        .filter(|m| m.kind != MarkKind::End)
        .map(|m| VLine {
            x: f64::from(m.at_ms) / 1000.0,
            label: m.name.clone(),
            color: if m.kind == MarkKind::Inject {
                FAULT_COLOUR
            } else {
                STEP_COLOUR
            },
        })
        .collect();
    if let Some(t) = tel.iter().find(|t| t.fault != FaultCode::None) {
        v.push(VLine {
            x: t_s(t),
            label: format!("fault detected: {}", t.fault.words()),
            color: FAULT_COLOUR,
        });
    }
    v
}

fn speed_figure(axis: usize, tel: &[Telemetry], marks: &[Mark]) -> Figure {
    let (name, symbol) = [("precession", "w1"), ("spin", "w2")][axis];
    let pick = |t: &Telemetry| if axis == 0 { t.precession } else { t.spin };
    let points = |value: &dyn Fn(&Telemetry) -> i16| -> Vec<(f64, f64)> {
        tel.iter()
            .map(|t| (t_s(t), f64::from(value(t)) / 1000.0))
            .collect()
    };
    let mut fig = log::speed_figure(
        format!("Demo: {name} motor {symbol}, set vs measured (telemetry)"),
        "device time, s",
        symbol,
        [
            points(&|t| pick(t).set_mrad_s),
            points(&|t| pick(t).measured_mrad_s),
        ],
        vec![
            "set: the commanded target; measured: the".into(),
            "rig's pulse-based estimate (50 frames/s).".into(),
            "Red lines: fault injected / detected.".into(),
            "The drive duties are in telemetry.csv.".into(),
        ],
    );
    fig.vlines = markers(marks, tel);
    fig
}

fn residence_figure(tel: &[Telemetry], marks: &[Mark]) -> Figure {
    let ms = |r: Residence| match r {
        Residence::Ms(ms) => f64::from(ms) / 1000.0,
        _ => f64::NAN,
    };
    Figure {
        title: "Demo: predicted residence time at the measured bowl speed".into(),
        x_label: "device time, s".into(),
        y_label: "residence time, s".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        series: vec![
            Series {
                name: "flat (Eq. 6/7)".into(),
                points: tel.iter().map(|t| (t_s(t), ms(t.residence_flat))).collect(),
                mark: Style::Line,
                color: 0,
            },
            Series {
                name: "Coriolis (Eq. 10/11 corr.)".into(),
                points: tel
                    .iter()
                    .map(|t| (t_s(t), ms(t.residence_coriolis)))
                    .collect(),
                mark: Style::Dashed,
                color: 1,
            },
        ],
        hlines: Vec::new(),
        vlines: markers(marks, tel),
        notes: vec![
            "Gaps: the particle never leaves (bowl".into(),
            "too slow) or the motors are stopped.".into(),
        ],
    }
}

/// Writes the charts into `dir`; returns the files written and the charts left out (why).
pub fn write(dir: &Path, tel: &[Telemetry], marks: &[Mark]) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let mut written = Vec::new();
    let mut skipped = Vec::new();
    let figures = [
        ("speeds_precession", speed_figure(0, tel, marks)),
        ("speeds_spin", speed_figure(1, tel, marks)),
        ("residence", residence_figure(tel, marks)),
    ];
    for (name, fig) in figures {
        let svg = dir.join(format!("{name}.svg"));
        let png = dir.join(format!("{name}.png"));
        match fig.write_svg(&svg) {
            Ok(()) => {}
            // A rig that predicts no residence time at all: nothing to draw, say so.
            Err(PlotError::NoData) => {
                skipped.push(format!("{name}: no data to draw"));
                continue;
            }
            Err(e) => return Err(e).with_context(|| format!("chart {}", svg.display())),
        }
        fig.write_png(&png)
            .with_context(|| format!("chart {}", png.display()))?;
        written.push(svg);
        written.push(png);
    }
    Ok((written, skipped))
}
