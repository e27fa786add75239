//! Texture coordinates, normals, per-vertex colours, groups and materials:
//! read with the input, respected when planar regions are built, and carried
//! to the output from the carriers.
//!
//! Attributes are stored per triangle corner ([`Channel`]): a vertex on a
//! seam has a different value in each face around it. The construction does
//! not look at them except in one place: two exactly coplanar input faces
//! join one planar region only if the attributes allow a flip across their
//! edge ([`Attributes::keep_apart`]). Then every region carries one affine
//! field per attribute, so whatever refinement does inside it, interpolating
//! the corner values of [`Transfer::apply`] reproduces the input's
//! piecewise-linear mapping:
//! - an input vertex takes, bit for bit, its own value in the region of the
//!   output face;
//! - a vertex added on input edge (a, b) at parameter t takes
//!   `value(a) + t·(value(b) − value(a))`, with a's and b's values in the
//!   region of the output face (the side of the edge the face is on).
//!
//! Normals are interpolated linearly, not renormalized: the field a renderer
//! interpolates stays the same.

use glam::DVec3;

use crate::hash::FastMap;
use crate::mesh::{Carrier, FaceId, Surface};

/// "No value": a corner that the file gave none (only in a
/// [`crate::io::RawMesh`], before [`crate::io::finish`] checks them).
pub const NO_VALUE: u32 = u32::MAX;

/// How far the fourth corner of two coplanar faces may be from the affine
/// extension of the other three, relative to the largest value involved,
/// for the faces to count as carrying one affine field.
///
/// The extension is computed in double precision from barycentric
/// coordinates of moderate size: its rounding error is about 10·2⁻⁵³ ≈ 1e-15
/// of the values, three orders of magnitude below this. A flip across the
/// edge changes the interpolated value by at most the residual (the two
/// triangulations of the quad interpolate the same corners, and differ by
/// the residual times a barycentric weight ≤ 1), so a residual of 1e-12
/// keeps the mapping three orders of magnitude inside the 1e-9 that issue 6
/// asks for. Values that are not affine — texture coordinates printed with
/// six digits are off by ~1e-7 — are far above it, and their faces simply
/// stay apart (more splits, never a distorted mapping). Needle quads, whose
/// barycentric coordinates are huge, may be kept apart though affine: that
/// errs on the safe side too.
pub const AFFINE_TOLERANCE: f64 = 1e-12;

/// The largest number of values in one attribute (RGBA colour).
pub const MAX_DIM: usize = 4;

/// Which attribute a [`Channel`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Texture coordinates (OBJ `vt`, PLY `u v`, `s t` or `texture_u texture_v`).
    TexCoord,
    /// Normals (OBJ `vn`, PLY `nx ny nz`).
    Normal,
    /// Colours, each component in 0..1 (OBJ `v x y z r g b`, PLY
    /// `red green blue [alpha]`, integers scaled to 0..1).
    Color,
}

impl Kind {
    /// How messages name the attribute.
    pub fn name(self) -> &'static str {
        match self {
            Kind::TexCoord => "texture coordinates",
            Kind::Normal => "normals",
            Kind::Color => "colours",
        }
    }
}

/// One attribute of every corner: a pool of values of `dim` numbers each,
/// and for every corner the index of its value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Channel {
    /// Numbers per value: 1 to [`MAX_DIM`].
    pub dim: usize,
    /// The values, `dim` numbers each.
    pub values: Vec<f64>,
    /// The value of each corner: of triangle `t`, corner `k` has
    /// `corners[3 * t + k]` (in a [`crate::io::RawMesh`]: one per entry of
    /// its `indices`).
    pub corners: Vec<u32>,
}

impl Channel {
    /// An empty channel of `dim` numbers per value.
    pub fn new(dim: usize) -> Channel {
        Channel {
            dim,
            ..Channel::default()
        }
    }

    /// Number of values in the pool.
    pub fn n_values(&self) -> usize {
        self.values.len().checked_div(self.dim).unwrap_or(0)
    }

    /// Value number `i` (empty if out of range).
    pub fn value(&self, i: u32) -> &[f64] {
        let start = i as usize * self.dim;
        self.values.get(start..start + self.dim).unwrap_or(&[])
    }

    /// The value of corner `c` (empty if out of range).
    pub fn corner(&self, c: usize) -> &[f64] {
        self.corners.get(c).map_or(&[], |&i| self.value(i))
    }

    /// Appends a value, returning its index.
    pub fn push(&mut self, value: &[f64]) -> u32 {
        let i = self.n_values() as u32;
        self.values.extend_from_slice(value);
        i
    }
}

/// The object, group and material of a face in an OBJ file: each the rest of
/// its statement's line, verbatim (`None`: no such statement before it).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Group {
    /// `o` name.
    pub object: Option<String>,
    /// `g` names.
    pub group: Option<String>,
    /// `usemtl` name.
    pub material: Option<String>,
}

/// The attributes of a triangle mesh, per corner (see [`Channel`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Attributes {
    /// Texture coordinates.
    pub texcoords: Option<Channel>,
    /// Normals.
    pub normals: Option<Channel>,
    /// Colours.
    pub colors: Option<Channel>,
    /// The group of each face, an index into `groups`; empty when the file
    /// has no `o`, `g` or `usemtl`.
    pub face_group: Vec<u32>,
    /// The distinct groups, in order of first use.
    pub groups: Vec<Group>,
    /// The arguments of the file's `mtllib` statements, verbatim.
    pub mtllib: Vec<String>,
}

impl Attributes {
    /// Whether there is nothing to carry.
    pub fn is_empty(&self) -> bool {
        self.channels().next().is_none() && self.face_group.is_empty() && self.mtllib.is_empty()
    }

    /// The channels present.
    pub fn channels(&self) -> impl Iterator<Item = (Kind, &Channel)> {
        [
            (Kind::TexCoord, &self.texcoords),
            (Kind::Normal, &self.normals),
            (Kind::Color, &self.colors),
        ]
        .into_iter()
        .filter_map(|(k, c)| c.as_ref().map(|c| (k, c)))
    }

    /// The channel of `kind`, mutable.
    pub fn channel_mut(&mut self, kind: Kind) -> &mut Option<Channel> {
        match kind {
            Kind::TexCoord => &mut self.texcoords,
            Kind::Normal => &mut self.normals,
            Kind::Color => &mut self.colors,
        }
    }

    /// Whether two input triangles `f1` and `f2` of `triangles`, which share
    /// an edge and lie exactly in one plane, must stay in different planar
    /// regions because a flip across their edge could not keep the
    /// attributes. They must be: in different groups; or on a seam (the two
    /// faces give a shared vertex different values); or carrying a field
    /// that is not one affine function on the two faces (the fourth corner's
    /// value is off the affine extension of the other face's by more than
    /// [`AFFINE_TOLERANCE`]).
    pub fn keep_apart(&self, positions: &[DVec3], triangles: &[[u32; 3]], f1: u32, f2: u32) -> bool {
        let (f1, f2) = (f1 as usize, f2 as usize);
        if self.face_group.get(f1) != self.face_group.get(f2) {
            return true;
        }
        let (Some(t1), Some(t2)) = (triangles.get(f1), triangles.get(f2)) else {
            return true;
        };
        // The shared edge: corners k1 (a) and k1 + 1 (b) of t1, c opposite.
        let Some(k1) = (0..3).find(|&k| t2.contains(&t1[k]) && t2.contains(&t1[(k + 1) % 3])) else {
            return true;
        };
        let corner1 = |k: usize| 3 * f1 + (k1 + k) % 3;
        let at2 = |v: u32| t2.iter().position(|&w| w == v).map(|k| 3 * f2 + k);
        let (Some(a2), Some(b2)) = (at2(t1[k1]), at2(t1[(k1 + 1) % 3])) else {
            return true;
        };
        let Some(d2) = (0..3).map(|k| 3 * f2 + k).find(|&c| c != a2 && c != b2) else {
            return true;
        };
        let p = |v: u32| positions.get(v as usize).copied().unwrap_or(DVec3::NAN);
        let [a, b, c] = [0, 1, 2].map(|k| p(t1[(k1 + k) % 3]));
        let d = p(t2[d2 - 3 * f2]);
        // d = a + s·(b − a) + r·(c − a), exactly in the common plane.
        let (e1, e2, w) = (b - a, c - a, d - a);
        let n = e1.cross(e2);
        let nn = n.length_squared();
        let (s, r) = (w.cross(e2).dot(n) / nn, e1.cross(w).dot(n) / nn);
        if !(s.is_finite() && r.is_finite()) {
            return true;
        }
        self.channels().any(|(_, ch)| {
            let (va, vb, vc) = (ch.corner(corner1(0)), ch.corner(corner1(1)), ch.corner(corner1(2)));
            let vd = ch.corner(d2);
            if va != ch.corner(a2) || vb != ch.corner(b2) || [vb, vc, vd].iter().any(|v| v.len() != va.len()) {
                return true;
            }
            let scale = [va, vb, vc, vd]
                .iter()
                .flat_map(|v| v.iter())
                .fold(0.0f64, |m, x| m.max(x.abs()));
            (0..va.len()).any(|i| {
                let predicted = va[i] + s * (vb[i] - va[i]) + r * (vc[i] - va[i]);
                let residual = (vd[i] - predicted).abs();
                residual.is_nan() || residual > AFFINE_TOLERANCE * scale
            })
        })
    }
}

/// What the output's attributes are computed from: the input's attributes
/// and, for every input vertex and planar region around it, the corner whose
/// values it takes there. Made from the surface before refinement (which
/// never changes an input face's region).
#[derive(Clone, Debug)]
pub struct Transfer {
    attributes: Attributes,
    /// (input vertex, region) → input corner (3·triangle + k), lowest first.
    corner: FastMap<(u32, u32), u32>,
    /// Any corner of each input vertex, for a region it is not in (which
    /// cannot happen on a valid surface, but must not panic).
    any_corner: Vec<u32>,
    /// The group of each region (one group per region: see
    /// [`Attributes::keep_apart`]).
    region_group: Vec<u32>,
}

impl Transfer {
    /// Prepares the transfer of `attributes` (per corner of the input
    /// `triangles`) to refinements of `surface`, built from those triangles
    /// (face `i` is triangle `i`) and not yet refined.
    pub fn new(attributes: Attributes, triangles: &[[u32; 3]], surface: &Surface) -> Transfer {
        let mut corner = FastMap::default();
        let mut any_corner = vec![u32::MAX; surface.n_input_vertices];
        let mut region_group = vec![0u32; surface.n_regions];
        for (f, t) in triangles.iter().enumerate() {
            let region = surface.face_region.get(f).copied().unwrap_or(0);
            for (k, &v) in t.iter().enumerate() {
                let c = (3 * f + k) as u32;
                corner.entry((v, region)).or_insert(c);
                if let Some(any) = any_corner.get_mut(v as usize) {
                    *any = (*any).min(c);
                }
            }
            if let (Some(g), Some(slot)) = (attributes.face_group.get(f), region_group.get_mut(region as usize)) {
                *slot = *g;
            }
        }
        Transfer {
            attributes,
            corner,
            any_corner,
            region_group,
        }
    }

    /// The attributes given to the input.
    pub fn input(&self) -> &Attributes {
        &self.attributes
    }

    /// The attributes of the refined `surface`, per corner of
    /// `surface.triangles()`: see the module documentation.
    pub fn apply(&self, surface: &Surface) -> Attributes {
        let n_faces = surface.topo.n_faces();
        let input = &self.attributes;
        let corner_of = |v: u32, region: u32| {
            self.corner
                .get(&(v, region))
                .or_else(|| self.any_corner.get(v as usize))
                .map_or(usize::MAX, |&c| c as usize)
        };
        let mut out = Attributes {
            face_group: Vec::new(),
            groups: input.groups.clone(),
            mtllib: input.mtllib.clone(),
            ..Attributes::default()
        };
        if !input.face_group.is_empty() {
            out.face_group = (0..n_faces)
                .map(|f| {
                    let region = surface.face_region[f] as usize;
                    self.region_group.get(region).copied().unwrap_or(0)
                })
                .collect();
        }
        for (kind, channel) in input.channels() {
            let dim = channel.dim;
            let mut pooled = Channel::new(dim);
            pooled.corners.reserve(3 * n_faces);
            // Equal values share an entry of the pool.
            let mut index: FastMap<[u64; MAX_DIM], u32> = FastMap::default();
            let mut value = [0.0f64; MAX_DIM];
            for f in 0..n_faces {
                let region = surface.face_region[f];
                for v in surface.topo.face_vertices(FaceId(f as u32)) {
                    match surface.carriers[v.idx()] {
                        Carrier::Vertex(i) => {
                            let x = channel.corner(corner_of(i, region));
                            value = [0.0; MAX_DIM];
                            value[..x.len()].copy_from_slice(x);
                        }
                        Carrier::Edge { edge, t } => {
                            let [i0, i1] = surface.input_edges[edge as usize];
                            let x0 = channel.corner(corner_of(i0, region));
                            let x1 = channel.corner(corner_of(i1, region));
                            for (k, slot) in value.iter_mut().enumerate() {
                                let (a, b) = (x0.get(k).copied().unwrap_or(0.0), x1.get(k).copied().unwrap_or(0.0));
                                *slot = a + t * (b - a);
                            }
                        }
                    }
                    let key = value.map(f64::to_bits);
                    let next = pooled.n_values() as u32;
                    let i = *index.entry(key).or_insert(next);
                    if i == next {
                        pooled.values.extend_from_slice(&value[..dim]);
                    }
                    pooled.corners.push(i);
                }
            }
            *out.channel_mut(kind) = Some(pooled);
        }
        out
    }
}

/// Vertices split so that every vertex has one value per channel, for
/// formats that store attributes per vertex (PLY; OBJ colours): a vertex
/// whose corners have several values is written once per value, at the same
/// position, the copies after all other vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PerVertex {
    /// The input vertex of each written vertex (the first `n` are `0..n`).
    pub source: Vec<u32>,
    /// The triangles, on written vertices.
    pub triangles: Vec<[u32; 3]>,
    /// For each channel taken, the value index of each written vertex.
    pub values: Vec<Vec<u32>>,
}

impl PerVertex {
    /// Splits the `n_vertices` vertices of `triangles` by the values of
    /// `channels` (each per corner of `triangles`).
    pub fn new(n_vertices: usize, triangles: &[[u32; 3]], channels: &[&Channel]) -> PerVertex {
        let values_of = |c: usize| -> Vec<u32> {
            channels
                .iter()
                .map(|ch| ch.corners.get(c).copied().unwrap_or(0))
                .collect()
        };
        let mut first: Vec<Option<Vec<u32>>> = vec![None; n_vertices];
        let mut copies: FastMap<(u32, Vec<u32>), u32> = FastMap::default();
        let mut source: Vec<u32> = (0..n_vertices as u32).collect();
        let mut extra_values: Vec<Vec<u32>> = Vec::new();
        let mut out_triangles = Vec::with_capacity(triangles.len());
        for (f, t) in triangles.iter().enumerate() {
            let mut written = [0u32; 3];
            for (k, &v) in t.iter().enumerate() {
                let vals = values_of(3 * f + k);
                let slot = &mut first[v as usize];
                written[k] = match slot {
                    None => {
                        *slot = Some(vals);
                        v
                    }
                    Some(existing) if *existing == vals => v,
                    Some(_) => {
                        let next = source.len() as u32;
                        let id = *copies.entry((v, vals.clone())).or_insert(next);
                        if id == next {
                            source.push(v);
                            extra_values.push(vals);
                        }
                        id
                    }
                };
            }
            out_triangles.push(written);
        }
        let mut values = vec![Vec::with_capacity(source.len()); channels.len()];
        for vals in first
            .iter()
            .map(|v| v.clone().unwrap_or_else(|| vec![0; channels.len()]))
            .chain(extra_values)
        {
            for (column, x) in values.iter_mut().zip(vals) {
                column.push(x);
            }
        }
        PerVertex {
            source,
            triangles: out_triangles,
            values,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uv(values: &[[f64; 2]], corners: Vec<u32>) -> Channel {
        Channel {
            dim: 2,
            values: values.iter().flatten().copied().collect(),
            corners,
        }
    }

    /// A unit square split along its diagonal 0–2: (0, 1, 2) and (0, 2, 3).
    fn square() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        (p, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn affine_fields_join_others_stay_apart() {
        let (p, t) = square();
        let corners = vec![0, 1, 2, 0, 2, 3];
        let mut a = Attributes {
            texcoords: Some(uv(&[[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]], corners.clone())),
            ..Attributes::default()
        };
        assert!(!a.keep_apart(&p, &t, 0, 1));
        assert!(!a.keep_apart(&p, &t, 1, 0));
        // The fourth corner moved off the affine extension: apart.
        a.texcoords = Some(uv(&[[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.6]], corners.clone()));
        assert!(a.keep_apart(&p, &t, 0, 1));
        // Off by less than the tolerance: joined.
        a.texcoords = Some(uv(&[[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5 + 1e-17]], corners));
        assert!(!a.keep_apart(&p, &t, 0, 1));
        // A seam: vertex 2 has another value in the second face.
        a.texcoords = Some(uv(
            &[[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5], [0.5, 0.5000001]],
            vec![0, 1, 2, 0, 4, 3],
        ));
        assert!(a.keep_apart(&p, &t, 0, 1));
    }

    #[test]
    fn groups_stay_apart() {
        let (p, t) = square();
        let mut a = Attributes {
            face_group: vec![0, 1],
            groups: vec![Group::default(), Group::default()],
            ..Attributes::default()
        };
        assert!(a.keep_apart(&p, &t, 0, 1));
        a.face_group = vec![1, 1];
        assert!(!a.keep_apart(&p, &t, 0, 1));
    }

    #[test]
    fn per_vertex_copies_seam_vertices() {
        let ch = uv(
            &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 2.0]],
            vec![0, 1, 2, 0, 4, 3],
        );
        let pv = PerVertex::new(4, &[[0, 1, 2], [0, 2, 3]], &[&ch]);
        assert_eq!(pv.source, vec![0, 1, 2, 3, 2]);
        assert_eq!(pv.triangles, vec![[0, 1, 2], [0, 4, 3]]);
        assert_eq!(pv.values, vec![vec![0, 1, 2, 3, 4]]);
    }
}
