//! `delmesh render`: a picture of a mesh, the report's Figure 1 made by the
//! tool. Orthographic view from a chosen direction, faces shaded and painted
//! back to front; non-Delaunay edges drawn in red; with the input given too,
//! added vertices and the edges at them in blue. Each mark is painted right
//! after the nearest face it belongs to, so nearer faces hide it as they hide
//! faces. Also the bar chart of an `-all` sweep ([`bar_chart`]).
//!
//! Both build a [`Canvas`], written as SVG or PNG (see [`crate::draw`]).

use glam::{DVec2, DVec3};

use crate::draw::{Anchor, Canvas, Rgb, Shape};
use crate::geometry::{delaunay_excess, ACCEPT_TOLERANCE};
use crate::hash::FastMap;

/// Colour of non-Delaunay edges.
pub const NON_DELAUNAY: Rgb = Rgb(0xd6, 0x20, 0x20);
/// Colour of added vertices and the edges at them.
pub const ADDED: Rgb = Rgb(0x1f, 0x5f, 0xd6);

/// How to look at the mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Degrees around the vertical (y) axis.
    pub azimuth: f64,
    /// Degrees above the horizontal plane.
    pub elevation: f64,
    /// Picture width and height in pixels.
    pub size: u32,
}

impl Default for View {
    fn default() -> Self {
        View {
            azimuth: 30.0,
            elevation: 20.0,
            size: 800,
        }
    }
}

/// What the picture shows, for a caption.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Drawn {
    /// Faces drawn (facing the viewer).
    pub faces: usize,
    /// Interior edges with α + β > π + 1e-9 (all of them, seen or not).
    pub non_delaunay_edges: usize,
    /// Vertices not in the input (all of them, seen or not).
    pub added_vertices: usize,
}

/// Renders `triangles` over `positions` as an SVG document. Vertices whose
/// position is not in `input_positions` (when given) are "added".
pub fn render_svg(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    input_positions: Option<&[DVec3]>,
    view: &View,
) -> (String, Drawn) {
    let (canvas, drawn) = render(positions, triangles, input_positions, view);
    (canvas.to_svg(), drawn)
}

/// Draws `triangles` over `positions` (indices out of range are skipped).
/// Vertices whose position is not in `input_positions` (when given) are
/// "added".
pub fn render(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    input_positions: Option<&[DVec3]>,
    view: &View,
) -> (Canvas, Drawn) {
    let triangles: Vec<[u32; 3]> = triangles
        .iter()
        .copied()
        .filter(|t| t.iter().all(|&v| (v as usize) < positions.len()))
        .collect();
    let p = |v: u32| positions[v as usize];
    // (Whole turns off first: the radians of a huge azimuth lose its angle.)
    let (az, el) = (view.azimuth.rem_euclid(360.0).to_radians(), view.elevation.to_radians());
    // Camera looking along -forward; y is up.
    let forward = DVec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    let right = DVec3::Y.cross(forward).normalize_or(DVec3::X);
    let up = forward.cross(right);
    let project = |q: DVec3| DVec2::new(q.dot(right), q.dot(up));
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for t in &triangles {
        for &v in t {
            let q = project(p(v));
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    let size = view.size as f64;
    let margin = 0.04 * size;
    let extent = hi - lo;
    let scale = (size - 2.0 * margin) / extent.max_element().max(f64::MIN_POSITIVE);
    // Centred in both directions.
    let offset = (DVec2::splat(size) - extent * scale) / 2.0;
    let to_px = |q: DVec3| {
        let d = (project(q) - lo) * scale;
        DVec2::new(offset.x + d.x, size - offset.y - d.y)
    };
    let added: Vec<bool> = match input_positions {
        None => vec![false; positions.len()],
        Some(inp) => {
            let known: FastMap<[u64; 3], ()> = inp
                .iter()
                .map(|q| (crate::hash::position_key(q.to_array()), ()))
                .collect();
            positions
                .iter()
                .map(|q| !known.contains_key(&crate::hash::position_key(q.to_array())))
                .collect()
        }
    };
    // The face of each directed edge.
    let mut half: FastMap<(u32, u32), u32> = FastMap::default();
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            half.insert((t[i], t[(i + 1) % 3]), f as u32);
        }
    }
    // Faces facing the viewer, far to near; rank = place in that order.
    let mut order: Vec<(f64, usize)> = triangles
        .iter()
        .enumerate()
        .filter_map(|(f, t)| {
            let [a, b, c] = t.map(p);
            let n = (b - a).cross(c - a);
            (n.dot(forward) > 0.0).then(|| (((a + b + c) / 3.0).dot(forward), f))
        })
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut rank = vec![usize::MAX; triangles.len()];
    for (k, &(_, f)) in order.iter().enumerate() {
        rank[f] = k;
    }
    let seen = |f: u32| Some(rank[f as usize]).filter(|&r| r != usize::MAX);
    // Marks to paint after face `k`: (edge or vertex, colour, width).
    enum Mark {
        Edge(u32, u32, Rgb, f64),
        Vertex(u32),
    }
    let mut marks: Vec<Vec<Mark>> = (0..order.len()).map(|_| Vec::new()).collect();
    let apex = |t: &[u32; 3], a: u32, b: u32| t.iter().copied().find(|&v| v != a && v != b).unwrap_or(a);
    let mut non_delaunay = 0;
    let unit = (size / 800.0).clamp(0.6, 4.0);
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let twin = half.get(&(b, a)).copied();
            if twin.is_some() && a > b {
                continue; // the other side visits it
            }
            let bad = twin.is_some_and(|g| {
                let (c, d) = (apex(t, a, b), apex(&triangles[g as usize], a, b));
                delaunay_excess(p(a), p(b), p(c), p(d)) > ACCEPT_TOLERANCE
            });
            non_delaunay += bad as usize;
            let is_added = added[a as usize] || added[b as usize];
            if !bad && !is_added {
                continue;
            }
            let last = seen(f as u32).max(twin.and_then(seen));
            if let Some(k) = last {
                marks[k].push(if bad {
                    Mark::Edge(a, b, NON_DELAUNAY, (1.8 * unit).max(1.4))
                } else {
                    Mark::Edge(a, b, ADDED, (1.1 * unit).max(1.0))
                });
            }
        }
    }
    let mut last_face_of = vec![usize::MAX; positions.len()];
    for (k, &(_, f)) in order.iter().enumerate() {
        for v in triangles[f] {
            last_face_of[v as usize] = k;
        }
    }
    for (v, &k) in last_face_of.iter().enumerate() {
        if k != usize::MAX && added[v] {
            marks[k].push(Mark::Vertex(v as u32));
        }
    }
    let mut canvas = Canvas::new(view.size, view.size, Rgb::WHITE);
    let light = (forward + up * 0.5).normalize();
    let wire = Rgb(0x55, 0x55, 0x55);
    for (k, &(_, f)) in order.iter().enumerate() {
        let t = triangles[f];
        let [a, b, c] = t.map(p);
        let shade = (b - a).cross(c - a).normalize_or_zero().dot(light).clamp(0.0, 1.0);
        let g = (150.0 + 100.0 * shade) as u8;
        canvas.push(Shape::Polygon {
            points: t.iter().map(|&v| to_px(p(v))).collect(),
            fill: Rgb(g, g, g),
            stroke: Some((wire, 0.3)),
        });
        for m in &marks[k] {
            canvas.push(match *m {
                Mark::Edge(a, b, color, width) => Shape::Line {
                    from: to_px(p(a)),
                    to: to_px(p(b)),
                    color,
                    width,
                },
                Mark::Vertex(v) => Shape::Dot {
                    center: to_px(p(v)),
                    radius: (2.2 * unit).max(1.8),
                    fill: ADDED,
                },
            });
        }
    }
    let drawn = Drawn {
        faces: order.len(),
        non_delaunay_edges: non_delaunay,
        added_vertices: added.iter().filter(|&&a| a).count(),
    };
    (canvas, drawn)
}

/// One bar of [`bar_chart`].
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    /// Text left of the bar.
    pub label: String,
    /// Its length; `None` for a failed run (drawn as `note`, no bar).
    pub value: Option<f64>,
    /// Bar colour.
    pub color: Rgb,
    /// Text right of the bar (the value, or why there is none).
    pub note: String,
}

/// A horizontal bar chart: a title, then one row per bar, top to bottom,
/// with a light grid. Labels are left-aligned (pad them to make columns).
/// `legend` entries are drawn under the title.
pub fn bar_chart(title: &str, bars: &[Bar], legend: &[(String, Rgb)]) -> Canvas {
    let text = Rgb(0x22, 0x22, 0x22);
    let faint = Rgb(0x88, 0x88, 0x88);
    let row = 26.0;
    let pad = 16.0;
    let label_w = bars.iter().map(|b| Canvas::char_width(&b.label, 1)).fold(0.0, f64::max);
    let note_w = bars.iter().map(|b| Canvas::char_width(&b.note, 1)).fold(0.0, f64::max);
    let plot_w = 420.0;
    let width = (pad + label_w + 12.0 + plot_w + 8.0 + note_w + pad)
        .max(Canvas::char_width(title, 1) + 2.0 * pad)
        .ceil();
    let legend_h = if legend.is_empty() { 0.0 } else { row };
    let top = pad + 22.0 + legend_h + 8.0;
    let height = (top + row * bars.len() as f64 + 26.0 + pad).ceil();
    let mut c = Canvas::new(width as u32, height as u32, Rgb::WHITE);
    c.push(Shape::Text {
        at: DVec2::new(pad, pad + 8.0),
        scale: 1,
        color: text,
        anchor: Anchor::Start,
        text: title.into(),
    });
    let mut x = pad;
    for (name, color) in legend {
        let y = pad + 22.0 + row / 2.0;
        c.push(rect(x, y - 6.0, 12.0, 12.0, *color));
        c.push(Shape::Text {
            at: DVec2::new(x + 18.0, y),
            scale: 1,
            color: text,
            anchor: Anchor::Start,
            text: name.clone(),
        });
        x += 18.0 + Canvas::char_width(name, 1) + 24.0;
    }
    let max = bars
        .iter()
        .filter_map(|b| b.value)
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let step = nice_step(max / 5.0);
    let top_value = if step > 0.0 { (max / step).ceil() * step } else { 1.0 };
    let x0 = pad + label_w + 12.0;
    let bottom = top + row * bars.len() as f64;
    // Grid and axis labels.
    let mut g = 0.0;
    while step > 0.0 && g <= top_value * (1.0 + 1e-9) {
        let x = x0 + plot_w * g / top_value;
        c.push(Shape::Line {
            from: DVec2::new(x, top - 4.0),
            to: DVec2::new(x, bottom),
            color: Rgb(0xdd, 0xdd, 0xdd),
            width: 1.0,
        });
        c.push(Shape::Text {
            at: DVec2::new(x, bottom + 14.0),
            scale: 1,
            color: faint,
            anchor: Anchor::Middle,
            text: format_value(g),
        });
        g += step;
    }
    for (i, b) in bars.iter().enumerate() {
        let y = top + row * (i as f64 + 0.5);
        c.push(Shape::Text {
            at: DVec2::new(pad, y),
            scale: 1,
            color: text,
            anchor: Anchor::Start,
            text: b.label.clone(),
        });
        let len = b
            .value
            .filter(|v| v.is_finite() && *v > 0.0)
            .map_or(0.0, |v| plot_w * v / top_value);
        if b.value.is_some() {
            c.push(rect(x0, y - row * 0.34, len.max(1.0), row * 0.68, b.color));
        }
        c.push(Shape::Text {
            at: DVec2::new(x0 + len + 8.0, y),
            scale: 1,
            color: if b.value.is_some() { text } else { NON_DELAUNAY },
            anchor: Anchor::Start,
            text: b.note.clone(),
        });
    }
    c.push(Shape::Line {
        from: DVec2::new(x0, top - 4.0),
        to: DVec2::new(x0, bottom),
        color: faint,
        width: 1.0,
    });
    c
}

fn rect(x: f64, y: f64, w: f64, h: f64, fill: Rgb) -> Shape {
    Shape::Polygon {
        points: vec![
            DVec2::new(x, y),
            DVec2::new(x + w, y),
            DVec2::new(x + w, y + h),
            DVec2::new(x, y + h),
        ],
        fill,
        stroke: None,
    }
}

/// 1, 2 or 5 times a power of ten, at least `x` (0 for non-positive `x`).
fn nice_step(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return 0.0;
    }
    let p = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= x)
        .unwrap_or(10.0 * p)
}

/// A grid value: integers plainly, others with a few digits.
fn format_value(v: f64) -> String {
    if v == v.round() && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v:.3}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_the_faces_facing_the_viewer_and_marks_edges() {
        // A folded rhombus: its diagonal is non-Delaunay.
        let p = vec![
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(0.0, -0.5, 0.1),
        ];
        let t = [[0, 1, 2], [1, 0, 3]];
        let view = View {
            azimuth: 0.0,
            elevation: 0.0,
            size: 200,
        };
        let (svg, drawn) = render_svg(&p, &t, Some(&p[..3]), &view);
        assert_eq!(drawn.faces, 2);
        assert_eq!(drawn.non_delaunay_edges, 1);
        assert_eq!(drawn.added_vertices, 1);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert_eq!(svg.matches("<polygon").count(), 2);
        assert!(svg.contains("#d62020") && svg.contains("<circle"));
        // From behind, nothing faces the viewer.
        let (_, drawn) = render_svg(&p, &t, None, &View { azimuth: 180.0, ..view });
        assert_eq!(drawn.faces, 0);
        // Bad indices and empty meshes draw nothing, without panicking.
        let (c, drawn) = render(&p, &[[0, 1, 9]], None, &view);
        assert_eq!(drawn.faces, 0);
        assert!(c.to_png().is_ok());
        let _ = render(&[], &[], None, &view).0.to_png();
    }

    #[test]
    fn marks_are_painted_after_their_nearest_face() {
        let p = vec![
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(0.0, -0.5, 0.1),
        ];
        let t = [[0, 1, 2], [1, 0, 3]];
        let (c, _) = render(&p, &t, None, &View::default());
        let kinds: Vec<&str> = c
            .shapes
            .iter()
            .map(|s| match s {
                Shape::Polygon { .. } => "face",
                Shape::Line { .. } => "line",
                _ => "other",
            })
            .collect();
        assert_eq!(kinds, ["face", "face", "line"]);
    }

    #[test]
    fn chart_has_a_bar_per_value() {
        let bars = vec![
            Bar {
                label: "stack  s2 median".into(),
                value: Some(315.0),
                color: ADDED,
                note: "315".into(),
            },
            Bar {
                label: "queue  s0 -".into(),
                value: None,
                color: ADDED,
                note: "failed: work limit".into(),
            },
        ];
        let c = bar_chart("bunny.obj", &bars, &[("score 2".into(), ADDED)]);
        let svg = c.to_svg();
        assert!(svg.contains("failed: work limit") && svg.contains(">315<"));
        assert!(c.to_png().is_ok());
        assert_eq!(nice_step(75.0), 100.0);
        assert_eq!(nice_step(0.0), 0.0);
        assert_eq!(nice_step(120.0), 200.0);
    }
}
