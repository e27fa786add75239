//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

pub mod damage;
pub mod flat;

/// A small deterministic PRNG (xorshift64*), so tests need no `rand`.
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
    /// Uniform integer in 0..n.
    pub fn below(&mut self, n: u64) -> u64 {
        ((self.f64() * n as f64) as u64).min(n - 1)
    }
}

/// The `data/` folder of the crate.
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data")
}

/// The positions of an OBJ file's `v` lines, in order.
pub fn obj_vertices(path: &std::path::Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().take(3).map(|x| x.parse().unwrap()).collect();
            [x[0], x[1], x[2]]
        })
        .collect()
}

/// Every `.obj` in `data/`, sorted.
pub fn fixtures() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(data_dir())
        .expect("data/ exists")
        .map(|e| e.expect("readable data/").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    v.sort();
    v
}

/// A Möbius band of `n` quads, radius 2, half-width `w`: its `2n` vertices (a top and a bottom
/// one per step) and its quads `[top, bottom, next bottom, next top]`. After a full turn top
/// and bottom swap, so no orientation of the quads is consistent.
pub fn moebius_band(n: usize, w: f64) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let mut positions = Vec::new();
    for i in 0..n {
        let theta = std::f64::consts::TAU * i as f64 / n as f64;
        let phi = theta / 2.0;
        let centre = [2.0 * theta.cos(), 2.0 * theta.sin(), 0.0];
        let dir = [phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin()];
        positions.push([0, 1, 2].map(|k| centre[k] + w * dir[k]));
        positions.push([0, 1, 2].map(|k| centre[k] - w * dir[k]));
    }
    let quads = (0..n)
        .map(|i| {
            let (top, bottom) = (2 * i as u32, 2 * i as u32 + 1);
            let (next_top, next_bottom) = if i + 1 < n { (top + 2, bottom + 2) } else { (1, 0) };
            [top, bottom, next_bottom, next_top]
        })
        .collect();
    (positions, quads)
}

/// The corners of the unit cube: corner `i` at `(i & 1, (i >> 1) & 1, (i >> 2) & 1)`.
pub fn cube_corners() -> Vec<[f64; 3]> {
    (0..8u32).map(|i| [0, 1, 2].map(|k| f64::from((i >> k) & 1))).collect()
}

/// The quads of the unit cube of [`cube_corners`], each counter-clockwise seen from outside.
pub const CUBE_QUADS: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

/// The checker's report on the refined surface `s` against the input it was built from.
pub fn check_refined(input: &delmesh::io::InputMesh, s: &delmesh::mesh::Surface) -> delmesh::check::CheckReport {
    use delmesh::check::{check_meshes, Mesh3};
    check_meshes(
        &Mesh3 {
            positions: input.positions.clone(),
            triangles: input.triangles.clone(),
        },
        &Mesh3 {
            positions: s.positions.clone(),
            triangles: s.triangles(),
        },
    )
}

/// A cone-like fan of `n` triangles (`n` a multiple of 4, at least 4) around one apex vertex of
/// valence `n`, like the disks and cones of CAD exports: the apex at the origin (vertex 0) and a
/// closed rim whose points step through radii 1, 1/10, 1/100, 1/10 at heights -1, -1/10, 0,
/// 1/20. The triangles are not coplanar and the long spokes face angles near π, so refinement
/// must split spokes, adding several vertices on each, most of them close to the apex (at
/// distances 0.0078 to 0.14).
pub fn cone_fan(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    assert!(n >= 4 && n % 4 == 0, "the rim's pattern has period 4");
    const RIM: [(f64, f64); 4] = [(1.0, -1.0), (0.1, -0.1), (0.01, 0.0), (0.1, 0.05)];
    let mut positions = vec![[0.0, 0.0, 0.0]];
    for i in 0..n {
        let theta = std::f64::consts::TAU * i as f64 / n as f64;
        let (radius, height) = RIM[i % 4];
        positions.push([radius * theta.cos(), radius * theta.sin(), height]);
    }
    let triangles = (0..n as u32).map(|i| [0, 1 + i, 1 + (i + 1) % n as u32]).collect();
    (positions, triangles)
}

/// The sphere x² + y² + z² = 1/2 as marching tetrahedra leave it, over an `n`³ grid of
/// [-1, 1]³ (six tetrahedra per cube, one vertex per crossed grid edge, shared), with the
/// crossing's parameter along the grid edge clamped to [`tau`, 1 − `tau`], as implementations
/// do to avoid coincident vertices: where the field is almost zero at a grid point, the
/// vertices on its grid edges land `tau` of a cell from it and from each other
/// (near-coincident vertices, joined by needle triangles). Faces face outward.
pub fn marching_sphere(n: usize, tau: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    use std::collections::HashMap;
    let h = 2.0 / n as f64;
    let point = |[i, j, k]: [usize; 3]| [-1.0 + i as f64 * h, -1.0 + j as f64 * h, -1.0 + k as f64 * h];
    let field = |g: [usize; 3]| {
        let [x, y, z] = point(g);
        x * x + y * y + z * z - 0.5
    };
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut on_edge: HashMap<([usize; 3], [usize; 3]), u32> = HashMap::new();
    let mut vertex = |p: [usize; 3], q: [usize; 3], positions: &mut Vec<[f64; 3]>| {
        let key = (p.min(q), p.max(q));
        *on_edge.entry(key).or_insert_with(|| {
            let (a, b) = (field(p), field(q));
            let t = if a != b { a / (a - b) } else { 0.5 };
            let t = t.clamp(tau, 1.0 - tau);
            let (pa, pb) = (point(p), point(q));
            positions.push(std::array::from_fn(|c| pa[c] + t * (pb[c] - pa[c])));
            positions.len() as u32 - 1
        })
    };
    const TETS: [[usize; 4]; 6] = [
        [0, 1, 3, 7],
        [0, 1, 5, 7],
        [0, 2, 3, 7],
        [0, 2, 6, 7],
        [0, 4, 5, 7],
        [0, 4, 6, 7],
    ];
    let mut triangles = Vec::new();
    let mut push = |[a, b, c]: [u32; 3], positions: &Vec<[f64; 3]>| {
        if a == b || b == c || a == c {
            return;
        }
        let [pa, pb, pc] = [a, b, c].map(|v| positions[v as usize]);
        let (u, v) = (sub(pb, pa), sub(pc, pa));
        let normal = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let outward: f64 = (0..3).map(|i| normal[i] * (pa[i] + pb[i] + pc[i])).sum();
        triangles.push(if outward < 0.0 { [b, a, c] } else { [a, b, c] });
    };
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let corner = |c: usize| [i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)];
                for tet in TETS {
                    let q = tet.map(corner);
                    let inside: Vec<[usize; 3]> = q.iter().copied().filter(|&g| field(g) < 0.0).collect();
                    let outside: Vec<[usize; 3]> = q.iter().copied().filter(|&g| field(g) >= 0.0).collect();
                    match inside.len() {
                        1 | 3 => {
                            let (apex, others) = if inside.len() == 1 {
                                (inside[0], &outside)
                            } else {
                                (outside[0], &inside)
                            };
                            let t = [0, 1, 2].map(|m| vertex(apex, others[m], &mut positions));
                            push(t, &positions);
                        }
                        2 => {
                            let ([a, b], [c, d]) = ([inside[0], inside[1]], [outside[0], outside[1]]);
                            let p = [(a, c), (a, d), (b, d), (b, c)].map(|(x, y)| vertex(x, y, &mut positions));
                            push([p[0], p[1], p[2]], &positions);
                            push([p[0], p[2], p[3]], &positions);
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    (positions, triangles)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// [`marching_sphere`] written as `dir/sphere.obj`; returns its path.
pub fn marching_sphere_obj(dir: &std::path::Path, n: usize, tau: f64) -> PathBuf {
    let (positions, triangles) = marching_sphere(n, tau);
    let path = dir.join("sphere.obj");
    std::fs::write(&path, triangles_obj(&positions, &triangles)).unwrap();
    path
}

/// `positions` and `triangles` as OBJ text, coordinates in shortest round-trip form.
fn triangles_obj(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> String {
    let mut s = String::new();
    for p in positions {
        s += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]);
    }
    for t in triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// The triangles of an n × n grid of cells whose vertices are numbered row
/// by row (`(n + 1)` per row), with alternating diagonals.
pub fn grid_triangles(n: usize) -> Vec<[u32; 3]> {
    let mut triangles = Vec::new();
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 1 {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    triangles
}

/// The channel of `kind` of a mesh read back.
pub fn channel(m: &delmesh::io::InputMesh, kind: delmesh::attributes::Kind) -> Option<&delmesh::attributes::Channel> {
    use delmesh::attributes::Kind;
    match kind {
        Kind::TexCoord => m.attributes.texcoords.as_ref(),
        Kind::Normal => m.attributes.normals.as_ref(),
        Kind::Color => m.attributes.colors.as_ref(),
        Kind::Property(i) => m.attributes.properties.get(i as usize)?.channel.as_ref(),
    }
}

/// Barycentric coordinates of `p` in triangle `t` of `m`, and the distance
/// of `p` from its plane.
pub fn barycentric(m: &delmesh::io::InputMesh, t: usize, p: glam::DVec3) -> ([f64; 3], f64) {
    let [a, b, c] = m.triangles[t].map(|v| m.positions[v as usize]);
    let n = (b - a).cross(c - a);
    let nn = n.length_squared();
    let lb = (p - a).cross(c - a).dot(n) / nn;
    let lc = (b - a).cross(p - a).dot(n) / nn;
    ([1.0 - lb - lc, lb, lc], (p - a).dot(n).abs() / nn.sqrt())
}

/// A prism 2 high over the counter-clockwise outline `cap`, tilted by the
/// angles `about_y` and then `about_x` (in floating point: its caps are
/// flat only up to rounding), as OBJ and as OFF: its sides quads, its caps
/// one polygon each.
pub fn tilted_prism_with_polygon_caps(cap: &[[f64; 2]], about_y: f64, about_x: f64) -> (String, String) {
    let n = cap.len();
    let ((sy, cy), (sx, cx)) = (about_y.sin_cos(), about_x.sin_cos());
    let tilt = |[x, y, z]: [f64; 3]| {
        let (x, z) = (x * cy + z * sy, -x * sy + z * cy);
        [x, y * cx - z * sx, y * sx + z * cx]
    };
    let mut obj = String::new();
    let mut off = format!("OFF\n{} {} 0\n", 2 * n, n + 2);
    for h in [0.0, 2.0] {
        for &[x, y] in cap {
            let [x, y, z] = tilt([x, y, h]);
            obj += &format!("v {x:?} {y:?} {z:?}\n");
            off += &format!("{x:?} {y:?} {z:?}\n");
        }
    }
    for j in 0..n {
        let (a, b) = (j, (j + 1) % n);
        obj += &format!("f {} {} {} {}\n", a + 1, b + 1, n + b + 1, n + a + 1);
        off += &format!("4 {a} {b} {} {}\n", n + b, n + a);
    }
    let bottom: Vec<usize> = (0..n).rev().collect();
    let top: Vec<usize> = (n..2 * n).collect();
    for cap in [&bottom, &top] {
        obj += &format!("f{}\n", cap.iter().map(|v| format!(" {}", v + 1)).collect::<String>());
        off += &format!("{n}{}\n", cap.iter().map(|v| format!(" {v}")).collect::<String>());
    }
    (obj, off)
}
