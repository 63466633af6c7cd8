//! The figures drawn: SVG and PNG written with their text, lines kept within the data, segments
//! split at gaps, an empty figure refused.

use super::*;

#[test]
fn gaps_split_lines() {
    let f = Figure {
        title: String::new(),
        x_label: String::new(),
        y_label: String::new(),
        x_scale: Scale::Linear,
        y_scale: Scale::Log,
        series: vec![],
        hlines: Vec::new(),
        vlines: vec![],
        notes: vec![],
    };
    let s = Series {
        name: "s".into(),
        points: vec![
            (0.0, 1.0),
            (1.0, f64::INFINITY),
            (2.0, 10.0),
            (3.0, 0.0),
            (4.0, 100.0),
        ],
        mark: Mark::Line,
        color: 0,
    };
    let segs = f.segments(&s);
    assert_eq!(
        segs,
        vec![vec![(0.0, 0.0)], vec![(2.0, 1.0)], vec![(4.0, 2.0)]]
    );
}

fn sample() -> Figure {
    Figure {
        title: "Sample: y = x^2 and y = 1/x".into(),
        x_label: "x".into(),
        y_label: "y".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Log,
        series: vec![
            Series {
                name: "x^2".into(),
                points: (1..50).map(|i| (i as f64, (i * i) as f64)).collect(),
                mark: Mark::LinePoints,
                color: 0,
            },
            Series {
                name: "1/x".into(),
                points: (1..50).map(|i| (i as f64, 1.0 / i as f64)).collect(),
                mark: Mark::Dashed,
                color: 1,
            },
            Series {
                name: "never".into(),
                points: vec![(3.0, 1e-2)],
                mark: Mark::Crosses,
                color: 2,
            },
        ],
        hlines: Vec::new(),
        vlines: vec![VLine {
            x: 10.0,
            label: "bound".into(),
            color: 6,
        }],
        notes: vec!["a note".into()],
    }
}

#[test]
fn png_and_svg_are_written_with_text() {
    let dir = std::env::temp_dir().join(format!("bowl-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("s.png");
    let svg = dir.join("s.svg");
    let f = sample();
    f.write_png(&png).unwrap();
    f.write_svg(&svg).unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<svg") && text.contains("Sample: y = x^2"));
    assert!(text.contains("\n1e-2\n"), "log tick labels");
}

/// A line's label that would run past the plot's right edge into the legend ends at its line
/// (anchored right); one with room starts at its line.
#[test]
fn a_label_near_the_right_edge_ends_at_its_line() {
    let dir = std::env::temp_dir().join(format!("bowl-plot-label-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("s.svg");
    let mut f = sample();
    let long = "fault: spin motor: no sensor pulses (sensor lost or motor stalled)";
    f.vlines.push(VLine {
        x: 45.0,
        label: long.into(),
        color: 6,
    });
    f.write_svg(&svg).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    let tag_of = |label: &str| {
        let at = text.find(&format!("\n{label}")).unwrap();
        text[text[..at].rfind("<text").unwrap()..at].to_string()
    };
    assert!(
        tag_of(long).contains("text-anchor=\"end\""),
        "{}",
        tag_of(long)
    );
    assert!(
        !tag_of("bound").contains("text-anchor=\"end\""),
        "{}",
        tag_of("bound")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The topmost pixel row holding `rgb` in a PNG's plot area (left of the legend), if any.
fn top_row_of(path: &Path, rgb: RGBColor) -> Option<usize> {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bpp = info.line_size / info.width as usize;
    (0..info.height as usize).find(|&row| {
        buf[row * info.line_size..(row + 1) * info.line_size]
            .chunks(bpp)
            .take((WIDTH - LEGEND_WIDTH) as usize)
            .any(|p| p[0] == rgb.0 && p[1] == rgb.1 && p[2] == rgb.2)
    })
}

/// A noisy trace with sharp reversals (as a speed trace is) must not draw above its own
/// maximum in the PNG (its topmost pixel may not rise above that of a horizontal line drawn
/// at the data's maximum), and the PNG and the SVG draw it at the same height.
#[test]
fn png_lines_stay_within_the_data() {
    let n = 400;
    let trace: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let x = i as f64 * 0.05;
            let y = 2.6 + if i % 2 == 0 { 0.003 } else { -0.003 } * (1 + i % 7) as f64;
            (x, y)
        })
        .collect();
    let top = trace.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let f = Figure {
        title: "zigzag".into(),
        x_label: "t".into(),
        y_label: "w".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        series: vec![
            Series {
                name: "trace".into(),
                points: trace.clone(),
                mark: Mark::Line,
                color: 0,
            },
            Series {
                name: "its maximum".into(),
                points: vec![(0.0, top), (trace[n - 1].0, top)],
                mark: Mark::Line,
                color: 1,
            },
        ],
        hlines: Vec::new(),
        vlines: vec![],
        notes: vec![],
    };
    let dir = std::env::temp_dir().join(format!("bowl-plot-spikes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("zigzag.png");
    let svg = dir.join("zigzag.svg");
    f.write_png(&png).unwrap();
    f.write_svg(&svg).unwrap();
    let trace_top = top_row_of(&png, colour(0)).expect("the trace is drawn");
    let max_top = top_row_of(&png, colour(1)).expect("the maximum is drawn");
    assert!(
        trace_top + 1 >= max_top,
        "the trace reaches pixel row {trace_top}, its maximum is drawn at row {max_top}"
    );
    // The SVG draws the same trace in the same pixel space: its highest point lies within
    // the stroke's half width and a pixel of rounding of the PNG's topmost trace pixel.
    let text = std::fs::read_to_string(&svg).unwrap();
    let c = colour(0);
    let stroke = format!("stroke=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
    let svg_top = text
        .split("<polyline")
        .skip(1)
        .filter(|e| e.contains(&stroke))
        .filter_map(|e| e.split("points=\"").nth(1)?.split('"').next())
        .flat_map(|pts| pts.split_whitespace())
        .filter_map(|xy| {
            let (x, y) = xy.split_once(',')?;
            let (x, y) = (x.parse::<f64>().ok()?, y.parse::<f64>().ok()?);
            // Left of the legend, whose sample line has the same stroke.
            (x < f64::from(WIDTH - LEGEND_WIDTH)).then_some(y)
        })
        .fold(f64::INFINITY, f64::min);
    assert!(svg_top.is_finite(), "no trace polyline in the SVG");
    assert!(
        (trace_top as f64 - svg_top).abs() <= 2.0,
        "PNG top row {trace_top}, SVG top {svg_top}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn empty_figure_is_an_error_not_a_panic() {
    let mut f = sample();
    for s in &mut f.series {
        s.points = vec![(f64::NAN, 1.0), (1.0, -1.0)];
    }
    f.vlines.clear();
    let dir = std::env::temp_dir();
    let r = f.write_svg(&dir.join(format!("bowl-empty-{}.svg", std::process::id())));
    assert!(matches!(r, Err(PlotError::NoData)));
}

/// A line is drawn as strokes with one point per pixel, split where it turns back by more than
/// 120 degrees (the bitmap backend's wide joins of nearly opposite segments spiked to the plot's
/// edge: the demo's spin chart at its step down), each stroke ending where the next begins.
#[test]
fn a_line_that_turns_back_is_drawn_as_strokes_without_repeated_pixels() {
    // Pixels: the data's x and y rounded (1 data unit = 1 pixel).
    let px = |p: &(f64, f64)| (p.0.round() as i32, p.1.round() as i32);
    let line = [
        (0.0, 0.0),
        (1.0, 0.0),
        (1.2, 0.1), // the same pixel as (1, 0): left out
        (2.0, 0.0),
        (3.0, 45.0), // down...
        (3.0, 35.0), // ...and back up in the same column: a new stroke from (3, 45)
        (4.0, 35.0),
    ];
    let s = super::strokes(&line, px);
    assert_eq!(
        s,
        vec![
            vec![(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 45.0)],
            vec![(3.0, 45.0), (3.0, 35.0), (4.0, 35.0)],
        ]
    );
    // A right angle is no reversal: one stroke.
    let corner = [(0.0, 0.0), (5.0, 0.0), (5.0, 5.0)];
    assert_eq!(super::strokes(&corner, px).len(), 1);
}

/// A horizontal line is drawn across the plot with its label on it, right-anchored at the plot's
/// right end, and the axis keeps it off the frame.
#[test]
fn a_horizontal_line_is_drawn_inside_with_its_label() {
    let dir = std::env::temp_dir().join(format!("bowl-plot-hline-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("s.svg");
    let mut f = Figure::linear(
        "h".into(),
        "x",
        "y",
        vec![Series {
            name: "data".into(),
            points: vec![(0.0, 0.97), (1.0, 1.8)],
            mark: Mark::Points,
            color: 0,
        }],
        &[],
    );
    f.hlines.push(HLine {
        y: 3.0,
        label: "settling target 3 s".into(),
        color: 7,
    });
    let (_, y) = f.axes().unwrap();
    assert!(y.hi - 3.0 >= 0.03 * (y.hi - y.lo), "{y:?}");
    f.write_svg(&svg).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    let at = text
        .find("\nsettling target 3 s")
        .expect("the label is drawn");
    let tag = &text[text[..at].rfind("<text").unwrap()..at];
    assert!(tag.contains("text-anchor=\"end\""), "{tag}");
    std::fs::remove_dir_all(&dir).unwrap();
}
