//! Texture coordinates, normals, per-vertex colours, groups and materials,
//! and a PLY file's other vertex and face properties: read with the input,
//! respected when planar regions are built, and carried to the output from
//! the carriers.
//!
//! Attributes are stored per triangle corner ([`Channel`]): a vertex on a
//! seam has a different value in each face around it. The construction does
//! not look at them except in one place: exactly coplanar input faces join
//! one planar region (whose inner edges may be flipped) only if the
//! attributes allow it ([`AttributeCuts`]): never across a seam or between
//! groups; as a whole where each attribute is one affine field over the
//! faces within a [`Tolerances`] (file formats round values, so exactly
//! affine values are rare); else only two by two, where the values are
//! affine on the two faces exactly ([`Attributes::keep_apart`]). Then every
//! region carries one affine field per attribute (within the tolerance),
//! so whatever refinement does inside it, interpolating the corner values
//! of [`Transfer::apply`] reproduces the input's piecewise-linear mapping
//! (within twice the tolerance). One exception: the faces cut from one
//! polygon of the file always join (the file gives a polygon's values at
//! its corners only; how they spread inside is the cut's, delmesh's own:
//! [`crate::mesh::RegionCuts::polygon`]), and such a polygon whose values
//! are not one affine field joins nothing else; inside it the corners keep
//! their values and the fields follow the new triangles. Values are:
//! - an input vertex takes, bit for bit, its own value in the region of the
//!   output face;
//! - a vertex added on input edge (a, b) at parameter t takes
//!   `value(a) + t·(value(b) − value(a))` ([`interpolate`]: where that
//!   difference overflows, `(1 − t)·value(a) + t·value(b)`), with a's and
//!   b's values in the region of the output face (the side of the edge the
//!   face is on).
//!
//! Normals are interpolated linearly, not renormalized: the field a renderer
//! interpolates stays the same. A vertex property of an integer type (a
//! label, flags) is not interpolated: an added vertex takes the value of the
//! nearer end of its input edge ([`VertexProperty`]).
//!
//! A face property ([`FaceProperty`]: a face colour, a segment label) is
//! one value per face. Faces with different values never share a planar
//! region (as groups), so each output face lies in faces of one value and
//! takes it.

use std::cell::Cell;

use glam::{DVec2, DVec3};

use crate::hash::FastMap;
use crate::mesh::{Carrier, FaceId, RegionCuts, Surface};
use crate::union_find::UnionFind;

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

/// How far, relative to the largest magnitude of an attribute's values in
/// the region's piece of the mesh (its faces joined through shared
/// vertices: one object of the file), the values of a flat region may lie from one affine field for
/// the region to be flipped as a whole (`--attribute-tolerance`). Where it
/// is, any triangulation of the region interpolates a field within that
/// distance of the affine one, as the input's does: the output's field
/// differs from the input's by at most twice the tolerance there.
///
/// Exporters round what they write (Blender: texture coordinates to six
/// decimals, normals to four), and compute it from positions before
/// rounding those: the values of a textured flat polygon are then affine
/// only to about 1e-7 to 1e-4, and with [`AFFINE_TOLERANCE`] alone its
/// thin fan triangles, written as triangles, could not be flipped (64-gon
/// caps written as fans: 6,128 added vertices instead of none). 0 keeps
/// every field exact but inside polygons of the file, which are flipped
/// inside at any tolerance ([`RegionCuts::polygon`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Texture coordinates: 1e-5 (a 25th of a texel of a 4096 texture).
    pub texcoords: f64,
    /// Normals: 1e-3 (0.06° on a unit normal).
    pub normals: f64,
    /// Colours: 4e-3, about an 8-bit step (1/255 = 3.9e-3): most files
    /// store colours as bytes, rounded by up to half a step, so a smooth
    /// gradient on a flat part is affine only within about 2e-3.
    pub colors: f64,
    /// Other vertex properties ([`VertexProperty`]): 1e-5, as texture
    /// coordinates.
    pub properties: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            texcoords: 1e-5,
            normals: 1e-3,
            colors: 4e-3,
            properties: 1e-5,
        }
    }
}

impl Tolerances {
    /// The same tolerance for every attribute.
    pub fn all(tolerance: f64) -> Self {
        Tolerances {
            texcoords: tolerance,
            normals: tolerance,
            colors: tolerance,
            properties: tolerance,
        }
    }

    /// The tolerance of `kind`.
    pub fn of(&self, kind: Kind) -> f64 {
        match kind {
            Kind::TexCoord => self.texcoords,
            Kind::Normal => self.normals,
            Kind::Color => self.colors,
            Kind::Property(_) => self.properties,
        }
    }

    /// What a tolerance must be, as messages say it.
    pub const RANGE: &'static str = "a relative tolerance (a number from 0 to 1)";

    /// Refuses a tolerance that is not [`is_relative_tolerance`] (NaN,
    /// negative, infinite or above 1, as `--attribute-tolerance` refuses
    /// it) with [`crate::Error::Setting`] naming the attribute.
    pub fn validate(&self) -> crate::Result<()> {
        for (kind, name) in [
            (Kind::TexCoord, "texture coordinates tolerance"),
            (Kind::Normal, "normals tolerance"),
            (Kind::Color, "colours tolerance"),
            (Kind::Property(0), "vertex properties tolerance"),
        ] {
            let value = self.of(kind);
            if !is_relative_tolerance(value) {
                return Err(crate::Error::Setting {
                    name,
                    value,
                    expected: Self::RANGE,
                });
            }
        }
        Ok(())
    }
}

/// Whether `x` is a [`Tolerances`] value that the library and
/// `--attribute-tolerance` accept: a number from 0 to 1 (relative to the
/// attribute's largest magnitude in a region's object).
pub fn is_relative_tolerance(x: f64) -> bool {
    (0.0..=1.0).contains(&x)
}

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
    /// A PLY file's other vertex property: number `i` of
    /// [`Attributes::properties`].
    Property(u16),
}

/// The most vertex properties a file's vertices carry (the numbers of
/// [`Kind::Property`]); the reader leaves out the others, with a note.
pub const MAX_VERTEX_PROPERTIES: usize = u16::MAX as usize + 1;

impl Kind {
    /// How messages name the attribute (a vertex property by
    /// [`Attributes::name_of`], which knows its name).
    pub fn name(self) -> &'static str {
        match self {
            Kind::TexCoord => "texture coordinates",
            Kind::Normal => "normals",
            Kind::Color => "colours",
            Kind::Property(_) => "vertex property",
        }
    }

    /// 0, 1, 2 for texture coordinates, normals and colours (the readers'
    /// slots for them); `None` for a vertex property.
    pub fn fixed_index(self) -> Option<usize> {
        match self {
            Kind::TexCoord => Some(0),
            Kind::Normal => Some(1),
            Kind::Color => Some(2),
            Kind::Property(_) => None,
        }
    }
}

/// The type a PLY file declares for a property, which it is written back
/// as.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ValueType {
    /// `char` (`int8`).
    I8,
    /// `uchar` (`uint8`).
    U8,
    /// `short` (`int16`).
    I16,
    /// `ushort` (`uint16`).
    U16,
    /// `int` (`int32`).
    I32,
    /// `uint` (`uint32`).
    U32,
    /// `float` (`float32`).
    F32,
    /// `double` (`float64`).
    F64,
}

impl ValueType {
    /// Whether values are integers: then not interpolated (labels, flags).
    pub fn is_integer(self) -> bool {
        !matches!(self, ValueType::F32 | ValueType::F64)
    }

    /// The type's name in a PLY header.
    pub fn ply_name(self) -> &'static str {
        match self {
            ValueType::I8 => "char",
            ValueType::U8 => "uchar",
            ValueType::I16 => "short",
            ValueType::U16 => "ushort",
            ValueType::I32 => "int",
            ValueType::U32 => "uint",
            ValueType::F32 => "float",
            ValueType::F64 => "double",
        }
    }

    /// Bytes per value.
    pub fn size(self) -> usize {
        match self {
            ValueType::I8 | ValueType::U8 => 1,
            ValueType::I16 | ValueType::U16 => 2,
            ValueType::I32 | ValueType::U32 | ValueType::F32 => 4,
            ValueType::F64 => 8,
        }
    }

    /// Appends `x` as a little-endian value of this type: integers rounded
    /// and clamped to the type's range (values read from a file of this
    /// type are written back exactly), `float` rounded to the nearest.
    pub fn put_le(self, x: f64, out: &mut Vec<u8>) {
        // `as` saturates, and maps NaN to 0.
        match self {
            ValueType::I8 => out.push(x.round() as i8 as u8),
            ValueType::U8 => out.push(x.round() as u8),
            ValueType::I16 => out.extend_from_slice(&(x.round() as i16).to_le_bytes()),
            ValueType::U16 => out.extend_from_slice(&(x.round() as u16).to_le_bytes()),
            ValueType::I32 => out.extend_from_slice(&(x.round() as i32).to_le_bytes()),
            ValueType::U32 => out.extend_from_slice(&(x.round() as u32).to_le_bytes()),
            ValueType::F32 => out.extend_from_slice(&(x as f32).to_le_bytes()),
            ValueType::F64 => out.extend_from_slice(&x.to_le_bytes()),
        }
    }
}

/// A vertex property of a PLY file that is none of the attributes above
/// (MeshLab's `quality`, a scan's `confidence` or `intensity`, a
/// segmentation's `label`): one number per vertex, carried like them. An
/// added vertex interpolates its input edge's ends, or for an integer type
/// takes the value of the nearer end (the first at the middle): a label
/// stays a label.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexProperty {
    /// The property's name in the file.
    pub name: String,
    /// Its declared type, which the output keeps.
    pub ty: ValueType,
    /// The values (`dim` 1), per corner; `None` once dropped.
    pub channel: Option<Channel>,
}

/// A face property of a PLY file (face colours `red green blue`, a
/// segment label, MeshLab's `quality` or `flags`): one number per face.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceProperty {
    /// The property's name in the file.
    pub name: String,
    /// Its declared type, which the output keeps.
    pub ty: ValueType,
    /// One value per face (in a [`crate::io::RawMesh`]: per polygon of the
    /// file; else per triangle).
    pub values: Vec<f64>,
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

    /// Whether some corners have no value ([`NO_VALUE`]): an OBJ whose
    /// faces give texture coordinates or normals in some objects only. A
    /// triangle's three corners then have values, or none.
    pub fn is_partial(&self) -> bool {
        self.corners.contains(&NO_VALUE)
    }

    /// Appends a value, returning its index.
    pub fn push(&mut self, value: &[f64]) -> u32 {
        let i = self.n_values() as u32;
        self.values.extend_from_slice(value);
        i
    }
}

/// The object, group, material and smoothing group of a face in an OBJ
/// file: each the rest of its statement's line, verbatim (`None`: no such
/// statement before it).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Group {
    /// `o` name.
    pub object: Option<String>,
    /// `g` names.
    pub group: Option<String>,
    /// `usemtl` name.
    pub material: Option<String>,
    /// `s` smoothing group (`1`, `off`): which faces a renderer shades as
    /// one smooth surface where the file gives no normals.
    pub smoothing: Option<String>,
}

impl Group {
    /// Whether it names an object, group or material (not only a
    /// smoothing group).
    pub fn is_named(&self) -> bool {
        self.object.is_some() || self.group.is_some() || self.material.is_some()
    }
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
    /// has no `o`, `g`, `usemtl` or `s`.
    pub face_group: Vec<u32>,
    /// The distinct groups, in order of first use.
    pub groups: Vec<Group>,
    /// The arguments of the file's `mtllib` statements, verbatim.
    pub mtllib: Vec<String>,
    /// The texture images a PLY file names in `comment TextureFile NAME`
    /// lines (MeshLab's), kept only with `texcoords`: written back to a PLY
    /// output that has them.
    pub texture_files: Vec<String>,
    /// The type a PLY input declared for its colours, which a PLY output
    /// keeps: `float` or `double` (values in 0..1, written as they are),
    /// `ushort` (16-bit), else 8-bit, the usual (also for any other type).
    /// An OFF input's colours of whole numbers (0..255) are `uchar`, and an
    /// OFF output writes 8-bit colours (an integer type but `ushort`) as
    /// such numbers again, others as they are; `None` for an OBJ input and
    /// an OFF input's other colours.
    pub color_type: Option<ValueType>,
    /// A PLY file's other vertex properties, in the file's order.
    pub properties: Vec<VertexProperty>,
    /// A PLY file's face properties, in the file's order.
    pub face_properties: Vec<FaceProperty>,
}

impl Attributes {
    /// Whether there is nothing to carry.
    pub fn is_empty(&self) -> bool {
        self.channels().next().is_none()
            && self.face_group.is_empty()
            && self.mtllib.is_empty()
            && self.face_properties.is_empty()
    }

    /// Keeps only the groups some face uses, numbered by first use, and none at all when every
    /// face is in the default group (no `o`, `g`, `usemtl` or `s` before it), as a file read afresh
    /// would have them: after faces were dropped, the groups left are those of the faces kept.
    pub fn compact_groups(&mut self) {
        if self.groups.is_empty() {
            self.face_group = Vec::new();
            return;
        }
        let mut order = vec![u32::MAX; self.groups.len()];
        let mut used = Vec::new();
        for g in &mut self.face_group {
            // (An index past the groups, which no reader makes, is taken as the first.)
            let i = (*g as usize).min(order.len() - 1);
            if order[i] == u32::MAX {
                order[i] = used.len() as u32;
                used.push(std::mem::take(&mut self.groups[i]));
            }
            *g = order[i];
        }
        if used.len() > 1 || used.first().is_some_and(|g| *g != Group::default()) {
            self.groups = used;
        } else {
            self.face_group = Vec::new();
            self.groups = Vec::new();
        }
    }

    /// The channels present: texture coordinates, normals, colours, then
    /// the vertex properties.
    pub fn channels(&self) -> impl Iterator<Item = (Kind, &Channel)> {
        [
            (Kind::TexCoord, &self.texcoords),
            (Kind::Normal, &self.normals),
            (Kind::Color, &self.colors),
        ]
        .into_iter()
        .filter_map(|(k, c)| c.as_ref().map(|c| (k, c)))
        .chain(
            self.properties
                .iter()
                .enumerate()
                .filter_map(|(i, p)| p.channel.as_ref().map(|c| (Kind::Property(i as u16), c))),
        )
    }

    /// The channel of `kind`, mutable (a vertex property beyond the
    /// properties: added, unnamed, up to it).
    pub fn channel_mut(&mut self, kind: Kind) -> &mut Option<Channel> {
        match kind {
            Kind::TexCoord => &mut self.texcoords,
            Kind::Normal => &mut self.normals,
            Kind::Color => &mut self.colors,
            Kind::Property(i) => {
                let i = i as usize;
                if i >= self.properties.len() {
                    self.properties.resize_with(i + 1, || VertexProperty {
                        name: String::new(),
                        ty: ValueType::F64,
                        channel: None,
                    });
                }
                &mut self.properties[i].channel
            }
        }
    }

    /// How messages name the attribute `kind`: a vertex property by its
    /// name (`vertex property quality`).
    pub fn name_of(&self, kind: Kind) -> String {
        match kind {
            Kind::Property(i) => match self.properties.get(i as usize) {
                Some(p) => format!("vertex property {}", p.name),
                None => kind.name().to_owned(),
            },
            _ => kind.name().to_owned(),
        }
    }

    /// The vertex properties without their values, and the face
    /// properties without theirs: what a copy of these attributes on other
    /// corners and faces starts from.
    pub fn property_names(&self) -> (Vec<VertexProperty>, Vec<FaceProperty>) {
        let vertex = self.properties.iter().map(|p| VertexProperty {
            name: p.name.clone(),
            ty: p.ty,
            channel: None,
        });
        let face = self.face_properties.iter().map(|p| FaceProperty {
            name: p.name.clone(),
            ty: p.ty,
            values: Vec::new(),
        });
        (vertex.collect(), face.collect())
    }

    /// Whether faces `f1` and `f2` differ in a face property (bit for bit).
    fn face_values_differ(&self, f1: u32, f2: u32) -> bool {
        self.face_properties.iter().any(|p| {
            let value = |f: u32| p.values.get(f as usize).map(|x| x.to_bits());
            value(f1) != value(f2)
        })
    }

    /// Whether two input triangles `f1` and `f2` of `triangles`, which share
    /// an edge, can never share a planar region, whatever their values: they
    /// are in different groups, differ in a face property, or on a seam (the two faces give a shared
    /// vertex different values, or values of different sizes).
    pub fn apart(&self, triangles: &[[u32; 3]], f1: u32, f2: u32) -> bool {
        let Some(e) = SharedEdge::of(triangles, f1, f2) else {
            return true;
        };
        self.apart_along(&e, f1, f2)
    }

    /// [`Attributes::apart`], given the faces' shared edge.
    fn apart_along(&self, e: &SharedEdge, f1: u32, f2: u32) -> bool {
        self.face_group.get(f1 as usize) != self.face_group.get(f2 as usize)
            || self.face_values_differ(f1, f2)
            || self.channels().any(|(_, ch)| {
                let (va, vb) = (ch.corner(e.a1), ch.corner(e.b1));
                let (vc, vd) = (ch.corner(e.c1), ch.corner(e.d2));
                va != ch.corner(e.a2) || vb != ch.corner(e.b2) || [vb, vc, vd].iter().any(|v| v.len() != va.len())
            })
    }

    /// Whether two input triangles `f1` and `f2` of `triangles`, which share
    /// an edge and lie exactly in one plane, must stay in different planar
    /// regions because a flip across their edge could not keep the
    /// attributes exactly. They must be: [`Attributes::apart`]; or carrying
    /// a field that is not one affine function on the two faces (the fourth
    /// corner's value is off the affine extension of the other face's by
    /// more than [`AFFINE_TOLERANCE`]).
    pub fn keep_apart(&self, positions: &[DVec3], triangles: &[[u32; 3]], f1: u32, f2: u32) -> bool {
        let Some(e) = SharedEdge::of(triangles, f1, f2) else {
            return true;
        };
        if self.apart_along(&e, f1, f2) {
            return true;
        }
        let p = |c: usize| {
            triangles
                .get(c / 3)
                .and_then(|t| positions.get(t[c % 3] as usize))
                .copied()
                .unwrap_or(DVec3::NAN)
        };
        let [a, b, c, d] = [e.a1, e.b1, e.c1, e.d2].map(p);
        // d = a + s·(b − a) + r·(c − a), exactly in the common plane.
        let (e1, e2, w) = (b - a, c - a, d - a);
        let n = e1.cross(e2);
        let nn = n.length_squared();
        let (s, r) = (w.cross(e2).dot(n) / nn, e1.cross(w).dot(n) / nn);
        if !(s.is_finite() && r.is_finite()) {
            return true;
        }
        self.channels().any(|(_, ch)| {
            let [va, vb, vc, vd] = [e.a1, e.b1, e.c1, e.d2].map(|c| ch.corner(c));
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

/// The corners (3·triangle + k) of two triangles around their shared edge:
/// `a1`, `b1`, `c1` of the first (the edge a→b, c opposite), `a2`, `b2`,
/// `d2` of the second (d opposite).
struct SharedEdge {
    a1: usize,
    b1: usize,
    c1: usize,
    a2: usize,
    b2: usize,
    d2: usize,
}

impl SharedEdge {
    /// The shared edge of triangles `f1` and `f2`, if they have one.
    fn of(triangles: &[[u32; 3]], f1: u32, f2: u32) -> Option<SharedEdge> {
        let (f1, f2) = (f1 as usize, f2 as usize);
        let (t1, t2) = (triangles.get(f1)?, triangles.get(f2)?);
        let k1 = (0..3).find(|&k| t2.contains(&t1[k]) && t2.contains(&t1[(k + 1) % 3]))?;
        let corner1 = |k: usize| 3 * f1 + (k1 + k) % 3;
        let at2 = |v: u32| t2.iter().position(|&w| w == v).map(|k| 3 * f2 + k);
        let (a2, b2) = (at2(t1[k1])?, at2(t1[(k1 + 1) % 3])?);
        let d2 = (0..3).map(|k| 3 * f2 + k).find(|&c| c != a2 && c != b2)?;
        Some(SharedEdge {
            a1: corner1(0),
            b1: corner1(1),
            c1: corner1(2),
            a2,
            b2,
            d2,
        })
    }
}

/// The largest deviation from an affine field, relative to the attribute's
/// largest magnitude, that [`AttributeCuts::note`] puts down to rounding:
/// a little over half an 8-bit step (0.5 / 255 = 2.0e-3).
const ROUNDING_LIKE: f64 = 2.5e-3;

/// The piece of each triangle: triangles sharing a vertex are in one piece.
/// Pieces are numbered from 0 in the order of their first triangles;
/// returns the numbers and how many there are.
fn pieces(n_vertices: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, usize) {
    let mut sets = UnionFind::new(n_vertices);
    for &[a, b, c] in triangles {
        sets.union(a as usize, b as usize);
        sets.union(a as usize, c as usize);
    }
    let mut number = vec![u32::MAX; n_vertices];
    let mut n = 0;
    let piece = triangles
        .iter()
        .map(|t| {
            let root = sets.find(t[0] as usize);
            if number[root] == u32::MAX {
                number[root] = n;
                n += 1;
            }
            number[root]
        })
        .collect();
    (piece, n as usize)
}

/// The [`RegionCuts`] of a mesh's attributes, with [`Tolerances`]: what
/// [`crate::io::build_surface_with`] builds planar regions with. It also
/// records the flat regions it let be flipped as a whole though their
/// values are not exactly affine ([`AttributeCuts::note`]).
pub struct AttributeCuts<'a> {
    attributes: &'a Attributes,
    positions: &'a [DVec3],
    triangles: &'a [[u32; 3]],
    tolerances: Tolerances,
    /// The piece (set of faces joined through shared vertices: an object
    /// of the file) of each triangle, numbered from 0.
    piece: Vec<u32>,
    /// The largest magnitude of each channel's values in each piece:
    /// `scales[n_channels * piece + i]` for channel `i` (in the order of
    /// [`Attributes::channels`]). A region's tolerance is relative to its
    /// piece's, so that one object's large values (a floor tiled 0..100)
    /// do not loosen another's.
    scales: Vec<f64>,
    /// Regions found whole with values off one affine field by more than
    /// [`AFFINE_TOLERANCE`] (relative), and their faces.
    inexact: Cell<(usize, usize)>,
    /// The largest distance of such a region's values from its field, per
    /// channel.
    deviation: Vec<Cell<f64>>,
    /// The same relative to the piece's scale, per channel: what says
    /// whether rounding explains it.
    relative_deviation: Vec<Cell<f64>>,
    /// The first triangle of each triangle's polygon of the file
    /// ([`RegionCuts::polygon`]); empty: each triangle its own.
    first_of_polygon: Vec<u32>,
    /// Polygons flipped inside though their values are not one affine
    /// field over them, and their faces.
    loose: Cell<(usize, usize)>,
    /// Of the `inexact` regions, those with two faces cut from one polygon
    /// of the file, and those that are one polygon of the file: flipped
    /// inside there at any tolerance ([`RegionCuts::polygon`]), so that
    /// `--attribute-tolerance 0` does not keep their values exact there.
    inexact_polygons: Cell<(usize, usize)>,
}

impl<'a> AttributeCuts<'a> {
    /// The cuts that `attributes` of the triangles (`positions`,
    /// `triangles`) make, with `tolerances`.
    pub fn new(
        attributes: &'a Attributes,
        positions: &'a [DVec3],
        triangles: &'a [[u32; 3]],
        tolerances: Tolerances,
    ) -> AttributeCuts<'a> {
        let n_channels = attributes.channels().count();
        let (piece, n_pieces) = if n_channels == 0 {
            (Vec::new(), 0)
        } else {
            pieces(positions.len(), triangles)
        };
        let mut scales = vec![0.0f64; n_channels * n_pieces];
        for (i, (_, ch)) in attributes.channels().enumerate() {
            for (c, &piece) in (0..ch.corners.len()).zip(piece.iter().flat_map(|p| [p; 3])) {
                let scale = &mut scales[n_channels * piece as usize + i];
                *scale = ch.corner(c).iter().fold(*scale, |m, x| m.max(x.abs()));
            }
        }
        let cells = || (0..n_channels).map(|_| Cell::new(0.0)).collect();
        AttributeCuts {
            attributes,
            positions,
            triangles,
            tolerances,
            piece,
            scales,
            inexact: Cell::new((0, 0)),
            deviation: cells(),
            relative_deviation: cells(),
            first_of_polygon: Vec::new(),
            loose: Cell::new((0, 0)),
            inexact_polygons: Cell::new((0, 0)),
        }
    }

    /// The same cuts, knowing the polygon of the file each triangle was cut
    /// from (`polygons`, as [`crate::io::InputMesh::triangle_polygon`]:
    /// one number per triangle, those of one polygon consecutive; empty,
    /// or of another length, for none).
    pub fn with_polygons(mut self, polygons: &[u32]) -> Self {
        if polygons.len() == self.triangles.len() && polygons.windows(2).any(|w| w[0] == w[1]) {
            let mut first = 0u32;
            self.first_of_polygon = (0..polygons.len())
                .map(|t| {
                    if t > 0 && polygons[t] != polygons[t - 1] {
                        first = t as u32;
                    }
                    first
                })
                .collect();
        }
        self
    }

    /// The largest magnitude of each channel's values in the piece of
    /// triangle `f`.
    fn scales_of(&self, f: u32) -> &[f64] {
        let n = self.deviation.len();
        // (No channels: no pieces either, only groups.)
        let Some(&piece) = self.piece.get(f as usize) else {
            return &[];
        };
        let piece = piece as usize;
        &self.scales[n * piece..n * (piece + 1)]
    }

    /// A line for the printout when polygons of the file were flipped
    /// inside though their values are not one affine field over them
    /// ([`RegionCuts::polygon`]).
    pub fn polygon_note(&self) -> Option<String> {
        let (polygons, faces) = self.loose.get();
        (polygons > 0).then(|| {
            format!(
                "{polygons} polygon(s) of the file ({faces} triangles) may be flipped inside though their attributes \
                 are not one affine field there: the file gives them at the corners only, which keep them exactly \
                 (inside, they follow the new triangles)"
            )
        })
    }

    /// A line for the printout when some flat regions were let be flipped as
    /// a whole though their values are affine only within the tolerance:
    /// how many, how far each attribute was from affine, and so how far
    /// it may move there.
    pub fn note(&self) -> Option<String> {
        let (regions, faces) = self.inexact.get();
        if regions == 0 {
            return None;
        }
        let off: Vec<(String, f64, f64)> = self
            .attributes
            .channels()
            .zip(&self.deviation)
            .zip(&self.relative_deviation)
            .filter(|((_, d), _)| d.get() > 0.0)
            .map(|(((kind, _), d), relative)| (self.attributes.name_of(kind), d.get(), relative.get()))
            .collect();
        let list = |f: &dyn Fn(&(String, f64, f64)) -> String| off.iter().map(f).collect::<Vec<_>>().join(" and ");
        // Rounding explains deviations up to half an 8-bit step (colours
        // stored as bytes); larger ones are the values' own.
        let rounded = off.iter().all(|&(_, _, relative)| relative <= ROUNDING_LIKE);
        // A polygon of the file is flipped inside at any tolerance: 0 keeps
        // exact only what lies outside polygons.
        let (in_polygons, one_polygon) = self.inexact_polygons.get();
        let exact = if one_polygon == regions {
            format!(
                "{} of the file, flipped inside at any --attribute-tolerance: the corners keep their values",
                if regions == 1 { "a polygon" } else { "polygons" }
            )
        } else if in_polygons > 0 {
            "--attribute-tolerance 0 keeps them exact but inside polygons of the file, whose corners keep their values"
                .to_string()
        } else {
            "--attribute-tolerance 0 keeps them exact".to_string()
        };
        Some(format!(
            "{regions} flat region{} ({faces} faces) may be flipped as a whole: their {} are affine there only within \
             {}{}, so the output's may move by up to {} ({exact})",
            if regions == 1 { "" } else { "s" },
            list(&|(name, _, _)| name.to_string()),
            list(&|(_, d, _)| format!("{d:.1e}")),
            if rounded { " (rounded values)" } else { "" },
            list(&|(_, d, _)| format!("{:.1e}", 2.0 * d)),
        ))
    }
}

impl RegionCuts for AttributeCuts<'_> {
    fn apart(&self, f1: u32, f2: u32) -> bool {
        self.attributes.apart(self.triangles, f1, f2)
    }

    /// Each vertex's corners sorted by region, each compared with the
    /// first of its region there, in every channel.
    fn regions_with_two_values(&self, region: &[u32]) -> Vec<u32> {
        let channels: Vec<&Channel> = self.attributes.channels().map(|(_, ch)| ch).collect();
        if channels.is_empty() {
            return Vec::new();
        }
        let n = self.positions.len();
        let (start, mut corners) = corners_by_vertex(self.triangles, n);
        let mut out = Vec::new();
        for v in 0..n {
            let at = &mut corners[start[v] as usize..start[v + 1] as usize];
            at.sort_unstable_by_key(|&c| region[c as usize / 3]);
            for run in at.chunk_by(|&a, &b| region[a as usize / 3] == region[b as usize / 3]) {
                let first = run[0] as usize;
                let differs = |c: &u32| channels.iter().any(|ch| ch.corner(*c as usize) != ch.corner(first));
                if run[1..].iter().any(differs) {
                    out.push(region[first / 3]);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Fits each component of each attribute over the faces' corners by
    /// least squares, as an affine function of the position in the
    /// faces' plane, and requires every corner within the tolerance of it.
    fn whole(&self, faces: &[u32]) -> bool {
        let corner_position = |c: usize| self.positions[self.triangles[c / 3][c % 3] as usize];
        let corners = || faces.iter().flat_map(|&f| (0..3).map(move |k| 3 * f as usize + k));
        // The plane's frame: its normal from the faces' area vectors (all
        // facing one way), the origin at the corners' mean.
        let (mut normal, mut origin) = (DVec3::ZERO, DVec3::ZERO);
        for &f in faces {
            let [a, b, c] = self.triangles[f as usize].map(|v| self.positions[v as usize]);
            normal += (b - a).cross(c - a);
            origin += a + b + c;
        }
        origin /= (3 * faces.len()) as f64;
        let Some(normal) = normal.try_normalize() else {
            return false;
        };
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let xy: Vec<DVec2> = corners()
            .map(|c| {
                let d = corner_position(c) - origin;
                DVec2::new(d.dot(u), d.dot(v))
            })
            .collect();
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for p in &xy {
            sxx += p.x * p.x;
            sxy += p.x * p.y;
            syy += p.y * p.y;
        }
        let det = sxx * syy - sxy * sxy;
        if !(det > 0.0 && det.is_finite()) {
            return false;
        }
        // (A region is one piece: its faces are joined through edges.)
        let scales = self.scales_of(faces[0]);
        let mut deviations = vec![0.0f64; scales.len()];
        for (i, ((kind, ch), &scale)) in self.attributes.channels().zip(scales).enumerate() {
            // A region without values of this channel (faces of a part of
            // the file that has none) is not bound by it.
            if corners().all(|c| ch.corner(c).is_empty()) {
                continue;
            }
            let tolerance = self.tolerances.of(kind) * scale;
            if tolerance.is_nan() || tolerance <= 0.0 || corners().any(|c| ch.corner(c).len() != ch.dim) {
                return false;
            }
            for k in 0..ch.dim {
                let value = |c: usize| ch.corner(c)[k];
                let mean = corners().map(value).sum::<f64>() / xy.len() as f64;
                let (mut sxz, mut syz) = (0.0, 0.0);
                for (p, c) in xy.iter().zip(corners()) {
                    let z = value(c) - mean;
                    sxz += p.x * z;
                    syz += p.y * z;
                }
                let gx = (sxz * syy - syz * sxy) / det;
                let gy = (syz * sxx - sxz * sxy) / det;
                for (p, c) in xy.iter().zip(corners()) {
                    let off = (value(c) - (mean + gx * p.x + gy * p.y)).abs();
                    if off.is_nan() || off > tolerance {
                        return false;
                    }
                    deviations[i] = deviations[i].max(off);
                }
            }
        }
        if deviations
            .iter()
            .zip(scales)
            .any(|(&d, &scale)| d > AFFINE_TOLERANCE * scale)
        {
            let (regions, n) = self.inexact.get();
            self.inexact.set((regions + 1, n + faces.len()));
            let mut polygons: Vec<u32> = faces.iter().map(|&f| self.polygon(f)).collect();
            polygons.sort_unstable();
            let (in_polygons, one_polygon) = self.inexact_polygons.get();
            self.inexact_polygons.set((
                in_polygons + polygons.windows(2).any(|w| w[0] == w[1]) as usize,
                one_polygon + (polygons[0] == polygons[polygons.len() - 1]) as usize,
            ));
            for (((cell, relative), &d), &scale) in self
                .deviation
                .iter()
                .zip(&self.relative_deviation)
                .zip(&deviations)
                .zip(scales)
            {
                cell.set(cell.get().max(d));
                relative.set(relative.get().max(d / scale));
            }
        }
        true
    }

    fn apart_within(&self, f1: u32, f2: u32) -> bool {
        self.attributes.keep_apart(self.positions, self.triangles, f1, f2)
    }

    fn polygon(&self, f: u32) -> u32 {
        self.first_of_polygon.get(f as usize).copied().unwrap_or(f)
    }

    fn polygons_flipped_inside(&self, polygons: usize, faces: usize) {
        self.loose.set((polygons, faces));
    }
}

/// The corners (3·triangle + k) of each vertex below `n` of `triangles`,
/// in increasing order: those of vertex `v` are
/// `corners[start[v]..start[v + 1]]` (a counting sort by vertex).
fn corners_by_vertex(triangles: &[[u32; 3]], n: usize) -> (Vec<u32>, Vec<u32>) {
    crate::mesh::group_by_key(n, triangles.iter().flatten().copied())
}

/// What the output's attributes are computed from: the input's attributes
/// and, for every input vertex and planar region around it, the corner whose
/// values it takes there. Made from the surface before refinement (which
/// never changes an input face's region).
#[derive(Clone, Debug)]
pub struct Transfer {
    attributes: Attributes,
    /// For each input vertex `v`, `corners[corner_start[v]..corner_start[v +
    /// 1]]`: (region, input corner (3·triangle + k)), one per region around
    /// `v`, the lowest corner of `v` in it, ordered by region (a vertex's
    /// short list, not a hash map: [`Transfer::apply`] looks one up per
    /// output corner, and a map of millions of entries costs a cache miss
    /// or two each time).
    corner_start: Vec<u32>,
    /// See `corner_start`.
    corners: Vec<(u32, u32)>,
    /// Any corner of each input vertex, for a region it is not in (which
    /// cannot happen on a valid surface, but must not panic).
    any_corner: Vec<u32>,
    /// An input triangle of each region, whose group and face properties
    /// the region's faces take (one of each per region: see
    /// [`Attributes::keep_apart`]).
    region_face: Vec<u32>,
}

impl Transfer {
    /// Prepares the transfer of `attributes` (per corner of the input
    /// `triangles`) to refinements of `surface`, built from those triangles
    /// (face `i` is triangle `i`) and not yet refined.
    pub fn new(attributes: Attributes, triangles: &[[u32; 3]], surface: &Surface) -> Transfer {
        let n = surface.n_input_vertices;
        let region_of = |f: usize| surface.face_region.get(f).copied().unwrap_or(0);
        let mut region_face = vec![0u32; surface.n_regions];
        for f in 0..triangles.len() {
            if let Some(slot) = region_face.get_mut(region_of(f) as usize) {
                *slot = f as u32;
            }
        }
        // Each vertex's corners, in corner order: its lowest first.
        let (mut corner_start, by_vertex) = corners_by_vertex(triangles, n);
        let any_corner: Vec<u32> = (0..n)
            .map(|v| {
                let (start, end) = (corner_start[v] as usize, corner_start[v + 1] as usize);
                by_vertex[start..end].first().copied().unwrap_or(u32::MAX)
            })
            .collect();
        let mut corners: Vec<(u32, u32)> = by_vertex.iter().map(|&c| (region_of(c as usize / 3), c)).collect();
        // By region, the lowest corner of each (a stable sort keeps corner
        // order within a region), then compacted in place.
        let mut kept = 0usize;
        for v in 0..n {
            let (start, end) = (corner_start[v] as usize, corner_start[v + 1] as usize);
            let list = &mut corners[start..end];
            list.sort_by_key(|&(region, _)| region);
            corner_start[v] = kept as u32;
            for i in start..end {
                if i == start || corners[i].0 != corners[i - 1].0 {
                    corners[kept] = corners[i];
                    kept += 1;
                }
            }
        }
        corner_start[n] = kept as u32;
        corners.truncate(kept);
        corners.shrink_to_fit();
        Transfer {
            attributes,
            corner_start,
            corners,
            any_corner,
            region_face,
        }
    }

    /// The input corner whose values input vertex `v` takes in `region`:
    /// its lowest corner there, else its lowest anywhere (`usize::MAX` for
    /// no vertex of the input).
    fn corner_of(&self, v: u32, region: u32) -> usize {
        let v = v as usize;
        let list = match (self.corner_start.get(v), self.corner_start.get(v + 1)) {
            (Some(&start), Some(&end)) => &self.corners[start as usize..end as usize],
            _ => &[],
        };
        match list.binary_search_by_key(&region, |&(r, _)| r) {
            Ok(i) => list[i].1 as usize,
            Err(_) => self.any_corner.get(v).map_or(usize::MAX, |&c| c as usize),
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
        // The input triangle whose group and face properties each face takes.
        let source: Vec<usize> = if input.face_group.is_empty() && input.face_properties.is_empty() {
            Vec::new()
        } else {
            (0..n_faces)
                .map(|f| {
                    let region = surface.face_region[f] as usize;
                    self.region_face.get(region).map_or(0, |&t| t as usize)
                })
                .collect()
        };
        let (properties, mut face_properties) = input.property_names();
        for (p, out) in input.face_properties.iter().zip(&mut face_properties) {
            out.values = source
                .iter()
                .map(|&t| p.values.get(t).copied().unwrap_or(0.0))
                .collect();
        }
        let mut out = Attributes {
            face_group: Vec::new(),
            groups: input.groups.clone(),
            mtllib: input.mtllib.clone(),
            texture_files: input.texture_files.clone(),
            color_type: input.color_type,
            properties,
            face_properties,
            ..Attributes::default()
        };
        if !input.face_group.is_empty() {
            out.face_group = source
                .iter()
                .map(|&t| input.face_group.get(t).copied().unwrap_or(0))
                .collect();
        }
        // Every channel in one pass over the faces: each output corner's
        // input corners are found once for all channels.
        let n_vertices = surface.positions.len();
        let mut pools: Vec<Pool> = input
            .channels()
            .map(|(kind, channel)| Pool::new(kind, channel, input, 3 * n_faces, n_vertices))
            .collect();
        let n_channels = pools.len();
        // A vertex's values depend on its region only, and are mostly the
        // same in all its regions: its last corner's region and value
        // numbers, which its next corners in that region take as they are,
        // and its first value numbers, which a value found equal to one
        // takes without a look in the pool's index (a cache miss or two on
        // a large mesh, where the index holds millions of values).
        if n_channels > 0 {
            let mut last_region = vec![u32::MAX; n_vertices];
            let mut last_value = vec![NO_VALUE; n_vertices * n_channels];
            let mut first_value = vec![NO_VALUE; n_vertices * n_channels];
            for f in 0..n_faces {
                let region = surface.face_region[f];
                for v in surface.topo.face_vertices(FaceId(f as u32)) {
                    let slots = v.idx() * n_channels..(v.idx() + 1) * n_channels;
                    if last_region[v.idx()] == region {
                        for (pool, &i) in pools.iter_mut().zip(&last_value[slots]) {
                            pool.found.corners.push(i);
                        }
                        continue;
                    }
                    last_region[v.idx()] = region;
                    // The input corners the value comes from, and the parameter.
                    let (c0, c1, t) = match surface.carriers[v.idx()] {
                        Carrier::Vertex(i) => (self.corner_of(i, region), None, 0.0),
                        Carrier::Edge { edge, t } => {
                            let [i0, i1] = surface.input_edges[edge as usize];
                            (self.corner_of(i0, region), Some(self.corner_of(i1, region)), t)
                        }
                    };
                    let memo = last_value[slots.clone()].iter_mut().zip(&mut first_value[slots]);
                    for (pool, (last, first)) in pools.iter_mut().zip(memo) {
                        let i = pool.value_index(c0, c1, t, *first);
                        pool.found.corners.push(i);
                        *last = i;
                        if *first == NO_VALUE {
                            *first = i;
                        }
                    }
                }
            }
        }
        for pool in pools {
            let kind = pool.kind;
            *out.channel_mut(kind) = Some(pool.into_channel());
        }
        out
    }
}

/// One channel's values on the output ([`Transfer::apply`]), as they are
/// found: appended in the order the faces' corners need them, equal ones
/// included, then numbered once each by [`Pool::into_channel`].
///
/// Numbering them as they come (a look in an index of the values for
/// every new one) took most of the time spent writing a large textured
/// mesh: each look is a cache and TLB miss in a table of millions of slots,
/// which the walk over the faces between two looks leaves no room to
/// overlap. In one pass over the values alone, the looks overlap (a 980k-face
/// textured torus: 0.65 s of index looks during the walk, 0.17 s after).
struct Pool<'a> {
    kind: Kind,
    /// The input's values.
    channel: &'a Channel,
    /// Integer properties take the nearer end's value.
    nearest: bool,
    /// The output's values in the order found (a value found equal to the
    /// one a vertex had first is not appended again), and the number of each
    /// corner's among them.
    found: Channel,
}

impl<'a> Pool<'a> {
    /// An empty pool for channel `kind` of `input`, with room for
    /// `corners` corners and `vertices` values (about one per vertex; more
    /// at seams, then grown).
    fn new(kind: Kind, channel: &'a Channel, input: &Attributes, corners: usize, vertices: usize) -> Pool<'a> {
        let mut found = Channel::new(channel.dim);
        found.corners.reserve(corners);
        found.values.reserve(vertices * channel.dim);
        Pool {
            kind,
            channel,
            nearest: matches!(kind, Kind::Property(i) if input.properties[i as usize].ty.is_integer()),
            found,
        }
    }

    /// The number of the value at input corner `c0`, or at `t` between
    /// corners `c0` and `c1`, among those found: `known` if the value there
    /// is equal to it (bit for bit), else appended; [`NO_VALUE`] where a
    /// corner has none (a region of faces without values).
    fn value_index(&mut self, c0: usize, c1: Option<usize>, t: f64, known: u32) -> u32 {
        let dim = self.found.dim;
        let mut value = [0.0f64; MAX_DIM];
        let x0 = self.channel.corner(c0);
        match c1 {
            None => {
                if x0.is_empty() {
                    return NO_VALUE;
                }
                value[..x0.len()].copy_from_slice(x0);
            }
            Some(c1) => {
                let x1 = self.channel.corner(c1);
                if x0.is_empty() || x1.is_empty() {
                    return NO_VALUE;
                }
                for (slot, (&a, &b)) in value.iter_mut().zip(x0.iter().zip(x1)) {
                    *slot = match self.nearest {
                        true if t <= 0.5 => a,
                        true => b,
                        false => interpolate(a, b, t),
                    };
                }
            }
        }
        let value = &value[..dim];
        if known != NO_VALUE && same_bits(self.found.value(known), value) {
            return known;
        }
        self.found.values.extend_from_slice(value);
        (self.found.n_values() - 1) as u32
    }

    /// The output's channel: the values found, each once
    /// ([`number_alike_values`]).
    fn into_channel(self) -> Channel {
        let mut channel = self.found;
        number_alike_values(&mut channel);
        channel
    }
}

/// Keeps one of each value of `channel` (equal bit for bit), in order of
/// first appearance, compacting its values in place, and renumbers its
/// corners to match: the numbers a map from each value to the count of
/// values before it would give, value by value.
fn number_alike_values(channel: &mut Channel) {
    let dim = channel.dim;
    let n = channel.n_values();
    let mut index = ValueIndex::with_room(n);
    let mut number = Vec::with_capacity(n);
    for r in 0..n {
        // (The values kept so far are `values[..dim * index.len]`, where
        // value `r` is, or after: a kept value moves down, never up, so
        // value `r` is still in its place.)
        let kept = index.len;
        let i = index.find_or_insert(&channel.values[r * dim..(r + 1) * dim], &channel.values, dim);
        if index.len > kept && kept != r {
            channel.values.copy_within(r * dim..(r + 1) * dim, kept * dim);
        }
        number.push(i);
    }
    channel.values.truncate(index.len * dim);
    if index.len < n {
        for c in channel.corners.iter_mut().filter(|c| **c != NO_VALUE) {
            *c = number[*c as usize];
        }
    }
}

/// Whether two values are equal bit for bit (so -0.0 is not 0.0, and a NaN
/// equals itself): how a pool tells its values apart.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The number of each value kept ([`number_alike_values`]), found by the
/// value's bits: open addressing with linear probing, each slot 8 bytes (the
/// value's number and 32 bits of its hash), the values themselves read from
/// the channel. A map holding the values too took 40 bytes a slot; on a mesh
/// of millions of values its page faults and cache misses were most of the
/// time spent writing the output.
struct ValueIndex {
    /// `tag << 32 | number`, or [`ValueIndex::EMPTY`].
    slots: Vec<u64>,
    /// How many slots are taken: the number of values numbered.
    len: usize,
}

impl ValueIndex {
    const EMPTY: u64 = u64::MAX;

    /// An index with room for about `values` values before it grows.
    fn with_room(values: usize) -> ValueIndex {
        // At most half full: a search then looks at 2.5 slots on average.
        let n = (2 * values).max(16).next_power_of_two();
        ValueIndex {
            slots: vec![Self::EMPTY; n],
            len: 0,
        }
    }

    /// The hash of a value's bits.
    fn hash(value: &[f64]) -> u64 {
        use std::hash::Hasher;
        let mut h = crate::hash::FastHasher::default();
        for x in value {
            h.write_u64(x.to_bits());
        }
        h.finish()
    }

    /// The number of `value` among the values numbered so far (equal bit
    /// for bit), number `i` being `values[dim * i..dim * (i + 1)]`; or, if
    /// none is equal, the next number (the count of values numbered so
    /// far), recorded as the value's: it is to be put there.
    fn find_or_insert(&mut self, value: &[f64], values: &[f64], dim: usize) -> u32 {
        if 2 * (self.len + 1) > self.slots.len() {
            self.grow(values, dim);
        }
        let h = Self::hash(value);
        let tag = h >> 32;
        let mask = self.slots.len() - 1;
        let mut i = h as usize & mask;
        loop {
            let slot = self.slots[i];
            if slot == Self::EMPTY {
                let next = self.len as u32;
                self.slots[i] = tag << 32 | u64::from(next);
                self.len += 1;
                return next;
            }
            let number = (slot as u32) as usize;
            if slot >> 32 == tag && same_bits(&values[dim * number..dim * (number + 1)], value) {
                return number as u32;
            }
            i = (i + 1) & mask;
        }
    }

    /// Twice the slots, every value numbered placed again.
    fn grow(&mut self, values: &[f64], dim: usize) {
        let mut bigger = ValueIndex::with_room(self.slots.len());
        let mask = bigger.slots.len() - 1;
        for number in 0..self.len {
            let h = Self::hash(&values[dim * number..dim * (number + 1)]);
            let mut i = h as usize & mask;
            while bigger.slots[i] != Self::EMPTY {
                i = (i + 1) & mask;
            }
            bigger.slots[i] = (h >> 32) << 32 | number as u64;
        }
        bigger.len = self.len;
        *self = bigger;
    }
}

/// How messages name some properties of `element` (`vertex`, `face`):
/// `vertex property quality`, `face properties (red, green, blue)`; `None`
/// for none. Past [`NAMED_PROPERTIES`] names, the rest are counted (`vertex
/// properties (p0, ..., p7 and 92 more)`): a message stays one readable
/// line however many a file declares.
pub fn properties_named(element: &str, names: &[&str]) -> Option<String> {
    match names {
        [] => None,
        [one] => Some(format!("{element} property {one}")),
        _ if names.len() > NAMED_PROPERTIES => Some(format!(
            "{element} properties ({} and {} more)",
            names[..NAMED_PROPERTIES].join(", "),
            names.len() - NAMED_PROPERTIES
        )),
        _ => Some(format!("{element} properties ({})", names.join(", "))),
    }
}

/// How many property names [`properties_named`] lists at most.
pub const NAMED_PROPERTIES: usize = 8;

/// The value at parameter `t` ∈ [0, 1] between `a` and `b`:
/// `a + t·(b − a)`, as positions are computed, unless `b − a` overflows
/// (values of opposite signs beyond ±f64::MAX / 2, such as texture
/// coordinates of ±1.7e308, gave ±inf); then `(1 − t)·a + t·b`, kept
/// between `a` and `b` (its rounding could pass f64::MAX): finite for finite
/// `a` and `b`.
pub fn interpolate(a: f64, b: f64, t: f64) -> f64 {
    let d = b - a;
    if d.is_finite() {
        a + t * d
    } else {
        ((1.0 - t) * a + t * b).clamp(a.min(b), a.max(b))
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
    /// `channels` (each per corner of `triangles`). Each vertex's first
    /// values are held in one flat array, and only a copy's in a map: a
    /// list of values per corner was a heap allocation each, 7.6 million on
    /// a textured million-face output.
    pub fn new(n_vertices: usize, triangles: &[[u32; 3]], channels: &[&Channel]) -> PerVertex {
        let m = channels.len();
        // The values of each vertex's first corner, `m` a vertex (0 for a
        // vertex no face uses).
        let mut first = vec![0u32; n_vertices * m];
        let mut seen = vec![false; n_vertices];
        let mut copies: FastMap<(u32, Vec<u32>), u32> = FastMap::default();
        let mut source: Vec<u32> = (0..n_vertices as u32).collect();
        // The values of each copy, `m` a copy.
        let mut copy_values: Vec<u32> = Vec::new();
        let mut out_triangles = Vec::with_capacity(triangles.len());
        let mut values_here = vec![0u32; m];
        for (f, t) in triangles.iter().enumerate() {
            let mut written = [0u32; 3];
            for (k, &v) in t.iter().enumerate() {
                for (x, channel) in values_here.iter_mut().zip(channels) {
                    *x = channel.corners.get(3 * f + k).copied().unwrap_or(0);
                }
                let v_first = &mut first[v as usize * m..(v as usize + 1) * m];
                written[k] = if !std::mem::replace(&mut seen[v as usize], true) {
                    v_first.copy_from_slice(&values_here);
                    v
                } else if *v_first == values_here[..] {
                    v
                } else {
                    let next = source.len() as u32;
                    let id = *copies.entry((v, values_here.clone())).or_insert(next);
                    if id == next {
                        source.push(v);
                        copy_values.extend_from_slice(&values_here);
                    }
                    id
                };
            }
            out_triangles.push(written);
        }
        let values = (0..m)
            .map(|j| {
                let mut column = Vec::with_capacity(source.len());
                column.extend(first.iter().skip(j).step_by(m));
                column.extend(copy_values.iter().skip(j).step_by(m));
                column
            })
            .collect();
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

    /// Up to eight names are listed, the rest counted.
    #[test]
    fn many_properties_are_counted_past_eight() {
        let names: Vec<String> = (0..100).map(|i| format!("p{i}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        assert_eq!(properties_named("vertex", &names[..0]), None);
        assert_eq!(properties_named("face", &names[..1]).unwrap(), "face property p0");
        assert_eq!(
            properties_named("vertex", &names[..8]).unwrap(),
            "vertex properties (p0, p1, p2, p3, p4, p5, p6, p7)"
        );
        assert_eq!(
            properties_named("vertex", &names).unwrap(),
            "vertex properties (p0, p1, p2, p3, p4, p5, p6, p7 and 92 more)"
        );
    }

    /// Values near ±f64::MAX interpolate to finite values between them
    /// (`a + t·(b − a)` gave ±inf); others exactly as before.
    #[test]
    fn interpolation_does_not_overflow() {
        let big = 1.7e308;
        for t in [0.0, 1e-9, 0.25, 0.3, 0.5, 0.7, 1.0 - 1e-12, 1.0] {
            for (a, b) in [
                (-big, big),
                (big, -big),
                (f64::MAX, -f64::MAX),
                (f64::MAX, f64::MAX),
                (-big, 0.0),
            ] {
                let x = interpolate(a, b, t);
                assert!(x.is_finite() && x >= a.min(b) && x <= a.max(b), "{a} {b} {t}: {x}");
            }
            assert_eq!(interpolate(0.25, 0.75, t), 0.25 + t * (0.75 - 0.25));
        }
        assert_eq!(interpolate(-big, big, 0.5), 0.0);
        assert_eq!(interpolate(-big, big, 0.0), -big);
        assert_eq!(interpolate(-big, big, 1.0), big);
    }

    /// 20,000 values of two numbers, some equal: those equal but for the
    /// sign of zero apart (bit for bit), the others many times each.
    fn values_with_repeats() -> Vec<[f64; 2]> {
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        (0..20_000u32)
            .map(|n| {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                match n % 5 {
                    0 => [0.0, -0.0],
                    1 => [-0.0, 0.0],
                    _ => [(rng % 3000) as f64 / 7.0, 0.5],
                }
            })
            .collect()
    }

    /// The index numbers values in order of first appearance, as a map of
    /// the values would, through its growth (from 16 slots).
    #[test]
    fn value_index_numbers_values_in_order_of_first_appearance() {
        let mut kept: Vec<f64> = Vec::new();
        let mut index = ValueIndex::with_room(0);
        let mut reference: FastMap<[u64; 2], u32> = FastMap::default();
        for (n, value) in values_with_repeats().into_iter().enumerate() {
            let expected = *reference
                .entry(value.map(f64::to_bits))
                .or_insert(kept.len() as u32 / 2);
            let i = index.find_or_insert(&value, &kept, 2);
            assert_eq!(i, expected, "value {n}");
            if i as usize == kept.len() / 2 {
                kept.extend_from_slice(&value);
            }
        }
        assert_eq!(kept.len() / 2, reference.len());
        assert!(index.slots.len() >= 2 * reference.len() && index.len == reference.len());
    }

    /// A channel whose values repeat keeps one of each, in order of first
    /// appearance, and its corners (some without a value) point at the same
    /// values as before.
    #[test]
    fn number_alike_values_keeps_one_of_each_and_renumbers_corners() {
        let values = values_with_repeats();
        let mut corners: Vec<u32> = (0..values.len() as u32).rev().step_by(3).collect();
        corners.extend([NO_VALUE, 0, NO_VALUE]);
        let mut channel = Channel {
            dim: 2,
            values: values.iter().flatten().copied().collect(),
            corners: corners.clone(),
        };
        number_alike_values(&mut channel);
        let mut reference: FastMap<[u64; 2], u32> = FastMap::default();
        let mut expected: Vec<f64> = Vec::new();
        for value in &values {
            reference.entry(value.map(f64::to_bits)).or_insert_with(|| {
                expected.extend_from_slice(value);
                (expected.len() / 2 - 1) as u32
            });
        }
        assert!(reference.len() < values.len() / 2, "the values repeat");
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&channel.values), bits(&expected));
        for (&before, &after) in corners.iter().zip(&channel.corners) {
            match before {
                NO_VALUE => assert_eq!(after, NO_VALUE),
                _ => {
                    let value = values[before as usize].map(f64::to_bits);
                    assert_eq!(after, reference[&value]);
                    assert_eq!(bits(channel.value(after)), value);
                }
            }
        }
        // Values that never repeat are left as they are.
        let mut alone = uv(&[[1.0, 2.0], [0.0, 0.0], [-0.0, 0.0]], vec![2, 0, 1]);
        number_alike_values(&mut alone);
        assert_eq!(alone.values, [1.0, 2.0, 0.0, 0.0, -0.0, 0.0]);
        assert_eq!(alone.corners, [2, 0, 1]);
    }

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
    fn nearly_affine_regions_are_whole_within_the_tolerance() {
        let (p, t) = square();
        let corners = vec![0, 1, 2, 0, 2, 3];
        let off = |dv: f64| Attributes {
            texcoords: Some(uv(
                &[[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5 + dv]],
                corners.clone(),
            )),
            ..Attributes::default()
        };
        // Off by 1e-7 (six printed decimals): not exactly affine, but
        // within the default tolerance, which the note reports.
        let a = off(1e-7);
        assert!(a.keep_apart(&p, &t, 0, 1));
        let cuts = AttributeCuts::new(&a, &p, &t, Tolerances::default());
        assert!(!cuts.apart(0, 1) && cuts.apart_within(0, 1));
        assert!(cuts.whole(&[0, 1]));
        let note = cuts.note().expect("a note");
        assert!(
            note.starts_with("1 flat region (2 faces) may be flipped as a whole"),
            "{note}"
        );
        let surface = Surface::with_region_cuts(p.clone(), &t, &cuts).unwrap();
        assert_eq!((surface.n_regions, surface.flat_edges_apart), (1, 0));
        // Tolerance 0: exact, so apart, and no note.
        let exact = AttributeCuts::new(&a, &p, &t, Tolerances::all(0.0));
        assert!(!exact.whole(&[0, 1]) && exact.note().is_none());
        let surface = Surface::with_region_cuts(p.clone(), &t, &exact).unwrap();
        assert_eq!((surface.n_regions, surface.flat_edges_apart), (2, 1));
        // Off by 0.1: beyond the tolerance.
        let b = off(0.1);
        assert!(!AttributeCuts::new(&b, &p, &t, Tolerances::default()).whole(&[0, 1]));
        // Exactly affine: whole, and nothing to note.
        let c = off(0.0);
        let cuts = AttributeCuts::new(&c, &p, &t, Tolerances::default());
        assert!(cuts.whole(&[0, 1]) && cuts.note().is_none());
    }

    /// A quad polygon of the file (0, 1, 2, 3), cut into (0, 1, 2) and
    /// (0, 2, 3), whose texture is not one affine field over it, beside a
    /// triangle (1, 4, 2) in its plane whose texture is one affine field
    /// with (0, 1, 2), exactly; and a second triangle (4, 5, 2) beyond it,
    /// affine with it too. The polygon is one region (its diagonal flips:
    /// the file gives its values at the corners only); the triangles are
    /// one region of their own, not joined to the polygon (a flip across
    /// its side 1–2 would spread the polygon's values over theirs). Without
    /// the polygon's numbers, each face of the quad is a face of the file
    /// and stays apart.
    #[test]
    fn a_polygon_is_flipped_inside_whatever_its_values_and_joins_nothing_else() {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(4.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(4.5, 0.5, 0.0),
            DVec3::new(5.0, 1.5, 0.0),
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [1, 4, 2], [4, 5, 2]];
        // u = x / 8, v = y / 2, but corner 3 off that field.
        let f = |q: DVec3| [q.x / 8.0, q.y / 2.0];
        let mut values: Vec<[f64; 2]> = p.iter().map(|&q| f(q)).collect();
        values[3][0] += 0.1;
        let a = Attributes {
            texcoords: Some(uv(&values, t.iter().flatten().copied().collect())),
            ..Attributes::default()
        };
        let polygons = [0, 0, 1, 2];
        let cuts = AttributeCuts::new(&a, &p, &t, Tolerances::default()).with_polygons(&polygons);
        assert!(cuts.apart_within(0, 1) && !cuts.apart_within(0, 2) && !cuts.apart_within(2, 3));
        assert_eq!((0..4).map(|f| cuts.polygon(f)).collect::<Vec<_>>(), [0, 0, 2, 3]);
        let surface = Surface::with_region_cuts(p.clone(), &t, &cuts).unwrap();
        let r = &surface.face_region;
        assert!(r[0] == r[1] && r[2] == r[3] && r[0] != r[2], "{r:?}");
        assert_eq!((surface.n_regions, surface.flat_edges_apart), (2, 1));
        let note = cuts.polygon_note().expect("a note");
        assert!(
            note.starts_with("1 polygon(s) of the file (2 triangles) may be flipped inside"),
            "{note}"
        );
        // Each triangle a face of its own: the quad's faces stay apart,
        // and the triangles join the one they are affine with.
        let cuts = AttributeCuts::new(&a, &p, &t, Tolerances::default());
        let surface = Surface::with_region_cuts(p.clone(), &t, &cuts).unwrap();
        let r = &surface.face_region;
        assert!(r[0] == r[2] && r[2] == r[3] && r[0] != r[1], "{r:?}");
        assert!(cuts.polygon_note().is_none());
        // Polygon numbers of the wrong length are ignored.
        let cuts = AttributeCuts::new(&a, &p, &t, Tolerances::default()).with_polygons(&[0, 0]);
        assert_eq!(cuts.polygon(1), 1);
    }

    #[test]
    fn a_seam_keeps_a_region_from_being_whole() {
        // Four triangles around the centre 4 of a square: a seam along 0-4
        // (the last face gives 0 and 4 other values), so the faces join
        // around the seam but the seam edge stays between two regions.
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.5, 0.5, 0.0),
        ];
        let t = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let values = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.5, 0.5],
            [0.0, 0.0 + 1e-8],
            [0.5, 0.5 + 1e-8],
        ];
        let a = Attributes {
            texcoords: Some(uv(&values, vec![0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 5, 6])),
            ..Attributes::default()
        };
        let cuts = AttributeCuts::new(&a, &p, &t, Tolerances::default());
        assert!(cuts.apart(3, 0));
        let surface = Surface::with_region_cuts(p.clone(), &t, &cuts).unwrap();
        assert!(surface.flat_edges_apart >= 1, "{}", surface.flat_edges_apart);
        let (f0, f3) = (surface.face_region[0], surface.face_region[3]);
        assert_ne!(f0, f3, "the seam's two faces share a region");
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
