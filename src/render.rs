//! `delmesh render`: a picture of a mesh as SVG, the report's Figure 1 made
//! by the tool. Orthographic view from a chosen direction, faces shaded and
//! painted back to front; non-Delaunay edges drawn in red; with the input
//! given too, added vertices and the edges at them in blue.

use std::fmt::Write as _;

use glam::{DVec2, DVec3};

use crate::geometry::{delaunay_excess, ACCEPT_TOLERANCE};
use crate::hash::FastMap;

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
    /// Interior edges with α + β > π + 1e-9.
    pub non_delaunay_edges: usize,
    /// Vertices not in the input.
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
    let (az, el) = (view.azimuth.to_radians(), view.elevation.to_radians());
    // Camera looking along -forward; y is up.
    let forward = DVec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    let right = DVec3::Y.cross(forward).normalize_or(DVec3::X);
    let up = forward.cross(right);
    let project = |p: DVec3| DVec2::new(p.dot(right), p.dot(up));
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for &p in positions {
        let q = project(p);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    let size = view.size as f64;
    let margin = 0.04 * size;
    let scale = (size - 2.0 * margin) / (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let to_px = |p: DVec3| {
        let q = (project(p) - lo) * scale;
        DVec2::new(margin + q.x, size - margin - q.y)
    };
    let added: Vec<bool> = match input_positions {
        None => vec![false; positions.len()],
        Some(inp) => {
            let known: FastMap<[u64; 3], ()> = inp.iter().map(|p| (p.to_array().map(f64::to_bits), ())).collect();
            positions
                .iter()
                .map(|p| !known.contains_key(&p.to_array().map(f64::to_bits)))
                .collect()
        }
    };
    // Non-Delaunay interior edges: pair the two directed uses of each edge.
    let mut half: FastMap<(u32, u32), u32> = FastMap::default();
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            half.insert((t[i], t[(i + 1) % 3]), f as u32);
        }
    }
    let apex = |t: &[u32; 3], a: u32, b: u32| t.iter().copied().find(|&v| v != a && v != b).unwrap_or(a);
    let mut bad_edges = Vec::new();
    for (&(a, b), &f) in &half {
        if a < b {
            if let Some(&g) = half.get(&(b, a)) {
                let (c, d) = (apex(&triangles[f as usize], a, b), apex(&triangles[g as usize], a, b));
                let p = |v: u32| positions[v as usize];
                if delaunay_excess(p(a), p(b), p(c), p(d)) > ACCEPT_TOLERANCE {
                    bad_edges.push((a, b));
                }
            }
        }
    }
    // Faces facing the viewer, far to near.
    let mut order: Vec<(f64, usize)> = triangles
        .iter()
        .enumerate()
        .filter_map(|(f, t)| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            let n = (b - a).cross(c - a);
            (n.dot(forward) > 0.0).then(|| (((a + b + c) / 3.0).dot(forward), f))
        })
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut visible = vec![false; triangles.len()];
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{0}\" viewBox=\"0 0 {0} {0}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>",
        view.size
    );
    let light = (forward + up * 0.5).normalize();
    for &(_, f) in &order {
        visible[f] = true;
        let t = triangles[f];
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let shade = (b - a).cross(c - a).normalize_or_zero().dot(light).clamp(0.0, 1.0);
        let g = (150.0 + 100.0 * shade) as u8;
        let [pa, pb, pc] = t.map(|v| to_px(positions[v as usize]));
        let _ = writeln!(
            svg,
            "<polygon points=\"{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}\" fill=\"rgb({g},{g},{g})\" stroke=\"#555\" stroke-width=\"0.3\" stroke-linejoin=\"round\"/>",
            pa.x, pa.y, pb.x, pb.y, pc.x, pc.y
        );
    }
    // Overlays on visible faces: edges at added vertices, then non-Delaunay edges.
    let seen_edge = |a: u32, b: u32| {
        half.get(&(a, b)).is_some_and(|&f| visible[f as usize])
            || half.get(&(b, a)).is_some_and(|&f| visible[f as usize])
    };
    let line = |svg: &mut String, a: u32, b: u32, color: &str, width: f64| {
        let (p, q) = (to_px(positions[a as usize]), to_px(positions[b as usize]));
        let _ = writeln!(
            svg,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{color}\" stroke-width=\"{width}\"/>",
            p.x, p.y, q.x, q.y
        );
    };
    for (&(a, b), _) in half.iter().filter(|(&(a, b), _)| a < b || !half.contains_key(&(b, a))) {
        if (added[a as usize] || added[b as usize]) && seen_edge(a, b) {
            line(&mut svg, a, b, "#1f5fd6", 0.8);
        }
    }
    let mut drawn_bad = 0;
    for &(a, b) in &bad_edges {
        drawn_bad += 1;
        if seen_edge(a, b) {
            line(&mut svg, a, b, "#d62020", 1.6);
        }
    }
    let mut on_screen = vec![false; positions.len()];
    for &(_, f) in &order {
        for v in triangles[f] {
            on_screen[v as usize] = true;
        }
    }
    for (v, &p) in positions.iter().enumerate() {
        if added[v] && on_screen[v] {
            let q = to_px(p);
            let _ = writeln!(
                svg,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"1.6\" fill=\"#1f5fd6\"/>",
                q.x, q.y
            );
        }
    }
    svg.push_str("</svg>\n");
    let drawn = Drawn {
        faces: order.len(),
        non_delaunay_edges: drawn_bad,
        added_vertices: added.iter().filter(|&&a| a).count(),
    };
    (svg, drawn)
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
    }
}
