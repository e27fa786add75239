//! Writing a mesh in each output format, with the attributes the format can
//! hold (seams split into per-vertex copies for PLY and OFF).

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use crate::attributes::{properties_named, Attributes, Channel, Kind, PerVertex, ValueType};
use crate::error::Result;

use super::*;

/// The output format for `path`, by extension; OBJ when it says nothing.
pub fn output_format(path: &Path) -> Format {
    path.file_name()
        .and_then(|n| n.to_str())
        .and_then(formats::format_from_name)
        .unwrap_or(Format::Obj)
}

/// What of `attributes` a file of `format` cannot hold, as a note names it
/// (`"normals, groups and materials"`), and the pronoun for it (`it` for a
/// single property, else `them`); `None` if it holds all.
/// OBJ holds every attribute but a PLY file's other vertex and face
/// properties; PLY all but groups, materials and smoothing groups, and channels that only
/// some faces have; OFF texture coordinates, normals, colours and face
/// colours ([`off_face_colors`]), not channels that only some faces have;
/// STL positions only.
pub(super) fn attributes_format_cannot_hold(attributes: &Attributes, format: Format) -> Option<(String, &'static str)> {
    let groups = !attributes.face_group.is_empty() || !attributes.mtllib.is_empty();
    let mut lost: Vec<String> = Vec::new();
    let mut properties: Vec<&str> = Vec::new();
    for (kind, channel) in attributes.channels() {
        // PLY and OFF store values per vertex: they have no "none" for the
        // vertices of faces without.
        let partial = matches!(format, Format::Ply | Format::Off) && channel.is_partial();
        let lose = match kind {
            Kind::Property(_) => format != Format::Ply,
            _ => format == Format::Stl || partial,
        };
        if !lose {
            continue;
        }
        match kind {
            Kind::Property(i) => properties.push(&attributes.properties[i as usize].name),
            _ if partial => lost.push(format!("{} of only some faces", kind.name())),
            _ => lost.push(kind.name().to_owned()),
        }
    }
    lost.extend(properties_named("vertex", &properties));
    let held = match format {
        Format::Ply => (0..attributes.face_properties.len()).collect(),
        Format::Off => off_face_colors(attributes).map_or_else(Vec::new, |(held, _)| held),
        Format::Obj | Format::Stl => Vec::new(),
    };
    let face_properties: Vec<&str> = (attributes.face_properties.iter().enumerate())
        .filter(|(i, _)| !held.contains(i))
        .map(|(_, p)| p.name.as_str())
        .collect();
    lost.extend(properties_named("face", &face_properties));
    if groups && format != Format::Obj {
        if !attributes.mtllib.is_empty() || attributes.groups.iter().any(crate::attributes::Group::is_named) {
            lost.extend(["groups".to_owned(), "materials".to_owned()]);
        }
        if attributes.groups.iter().any(|g| g.smoothing.is_some()) {
            lost.push("smoothing groups".to_owned());
        }
    }
    let (last, rest) = lost.split_last()?;
    Some(if rest.is_empty() {
        let single_property = properties.len() + face_properties.len() == 1;
        (last.to_string(), if single_property { "it" } else { "them" })
    } else {
        (format!("{} and {last}", rest.join(", ")), "them")
    })
}

/// The face properties an OFF file holds, as its face colours: `red`,
/// `green` and `blue` (as the OFF reader names them, and as PLY files
/// do), all `uchar` (written as whole numbers 0..255) or all `float` or
/// `double` (written as they are), and `alpha` if it is of the same kind.
/// Their places in [`Attributes::face_properties`], in that order, and how
/// they are written; `None` if there are none such.
fn off_face_colors(attributes: &Attributes) -> Option<(Vec<usize>, formats::ColorText)> {
    let properties = &attributes.face_properties;
    let find = |name: &str| properties.iter().position(|p| p.name == name);
    let text = |i: usize| match properties[i].ty {
        ValueType::U8 => Some(formats::ColorText::Bytes),
        ValueType::F32 | ValueType::F64 => Some(formats::ColorText::Floats),
        _ => None,
    };
    let mut held = vec![find("red")?, find("green")?, find("blue")?];
    let kind = text(held[0])?;
    if held.iter().any(|&i| text(i) != Some(kind)) {
        return None;
    }
    held.extend(find("alpha").filter(|&i| text(i) == Some(kind)));
    Some((held, kind))
}

/// Leaves out of `input` the attributes that a file of `format` cannot hold
/// (STL: all of them; PLY: groups, materials and smoothing groups, and texture coordinates,
/// normals or colours that only some faces have; OFF: those, a PLY file's
/// other vertex properties and its face properties but the face colours;
/// OBJ: a PLY file's other vertex and face properties), before its surface
/// is built: an attribute that will not be written must not keep flat
/// regions apart or cost splits (when OFF could not hold normals, a
/// smooth-shaded oval cylinder written as OFF got 21,256 added vertices for
/// normals it did not keep, and none without them). Returns the note that
/// says so, if anything was left out; `refining`: whether the note adds
/// that the mesh is refined without them (not under `--no-refine`).
pub fn drop_attributes_format_cannot_hold(input: &mut InputMesh, format: Format, refining: bool) -> Option<String> {
    let (lost, them) = attributes_format_cannot_hold(&input.attributes, format)?;
    let held_face_colors = off_face_colors(&input.attributes).map_or_else(Vec::new, |(held, _)| held);
    let a = &mut input.attributes;
    match format {
        Format::Stl => *a = Attributes::default(),
        Format::Ply | Format::Off => {
            for channel in [&mut a.texcoords, &mut a.normals, &mut a.colors] {
                if channel.as_ref().is_some_and(Channel::is_partial) {
                    *channel = None;
                }
            }
            if a.texcoords.is_none() {
                a.texture_files = Vec::new();
            }
            a.face_group = Vec::new();
            a.groups = Vec::new();
            a.mtllib = Vec::new();
            if format == Format::Off {
                a.properties = Vec::new();
                a.face_properties = (std::mem::take(&mut a.face_properties).into_iter().enumerate())
                    .filter_map(|(i, p)| held_face_colors.contains(&i).then_some(p))
                    .collect();
            }
        }
        Format::Obj => {
            a.properties = Vec::new();
            a.face_properties = Vec::new();
        }
    }
    let name = format.name();
    Some(if refining {
        format!("{lost} left out: {name} cannot hold {them} (the mesh is refined as without {them})")
    } else {
        format!("{lost} left out: {name} cannot hold {them}")
    })
}

/// Writes a triangle mesh atomically, in the format of `path`'s extension
/// (OBJ, OFF, PLY binary, STL binary; OBJ when the extension says nothing).
pub fn write_mesh(path: &Path, positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<()> {
    write_mesh_after(path, &VertexLines::default(), positions, triangles)
}

/// [`write_mesh`], with the vertex lines of the first vertices formatted
/// already (used only if `done` holds the lines of `path`'s format).
pub fn write_mesh_after(path: &Path, done: &VertexLines, positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<()> {
    stage_mesh_after(path, done, positions, triangles)?.commit()
}

/// [`write_mesh_after`], staged ([`stage`]): not yet renamed into place.
pub fn stage_mesh_after(
    path: &Path,
    done: &VertexLines,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Result<Staged> {
    let positions: &[[f64; 3]] = bytemuck_positions(positions);
    let format = output_format(path);
    stage(path, |w| match format {
        Format::Obj => obj::write_obj_after(w, done, positions, triangles),
        Format::Off => formats::write_off_after(w, done, positions, triangles),
        Format::Ply => formats::write_ply_binary(w, positions, triangles, None),
        Format::Stl => formats::write_stl_binary(w, positions, triangles),
    })
}

/// Writes a triangle mesh with its attributes (per corner of `triangles`,
/// as [`crate::attributes::Transfer::apply`] gives them) atomically, in the
/// format of `path`'s extension. OBJ keeps everything but a PLY input's
/// `TextureFile` comments (a note says so); PLY keeps texture
/// coordinates (`s t`, the first two numbers, and the `comment
/// TextureFile` lines of a PLY input), normals (`nx ny nz`),
/// colours (`red green blue [alpha]`, 8-bit, or a PLY input's float or
/// 16-bit type) and a PLY input's other vertex and face properties (in
/// their types), a vertex with several values
/// written once per value at the same position, the copies last (values
/// the file writes alike, such as colours equal as bytes, count as one); OFF
/// keeps texture coordinates (`ST`), normals (`N`) and colours (`C`:
/// whole numbers 0..255 if 8-bit, as an OFF input's whole numbers and a PLY
/// input's integer types but `ushort` are, else numbers as they are, always
/// with a decimal point) per vertex, split at seams as in PLY, and face
/// colours (the face properties `red green blue [alpha]` of an OFF or PLY
/// input, `uchar` as whole numbers, `float` or `double` as they are) after
/// each face's indices; STL keeps positions only.
pub fn write_mesh_with_attributes(
    path: &Path,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    attributes: &Attributes,
) -> Result<Written> {
    let (written, staged) = stage_mesh_with_attributes(path, positions, triangles, attributes)?;
    staged.commit()?;
    Ok(written)
}

/// [`write_mesh_with_attributes`], staged ([`stage`]): not yet renamed
/// into place.
pub fn stage_mesh_with_attributes(
    path: &Path,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    attributes: &Attributes,
) -> Result<(Written, Staged)> {
    let mut written = Written::default();
    let staged = stage(path, |w| {
        written = write_with_attributes_into(w, output_format(path), positions, triangles, attributes)?;
        Ok(())
    })?;
    Ok((written, staged))
}

/// What [`write_mesh_with_attributes`] would write besides the mesh's own
/// vertices in a file of `format`, found by writing it into nothing: for an
/// output that cannot be taken back once written (a stream), before it is.
pub fn written_with_attributes(
    format: Format,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    attributes: &Attributes,
) -> std::io::Result<Written> {
    write_with_attributes_into(&mut std::io::sink(), format, positions, triangles, attributes)
}

/// Writes the mesh with its attributes into `w` as a file of `format` (see
/// [`write_mesh_with_attributes`]).
fn write_with_attributes_into(
    w: &mut dyn Write,
    format: Format,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    attributes: &Attributes,
) -> std::io::Result<Written> {
    let p = bytemuck_positions(positions);
    let mut notes = Vec::new();
    if let Some((lost, them)) = attributes_format_cannot_hold(attributes, format) {
        notes.push(format!("{lost} not written: {} cannot hold {them}", format.name()));
    }
    let mut copies_of = Vec::new();
    let mut face_order = Vec::new();
    match format {
        Format::Obj => {
            face_order = obj::faces_in_file_order(triangles.len(), attributes).unwrap_or_default();
            if attributes.texcoords.is_some() && !attributes.texture_files.is_empty() {
                notes.push(format!(
                    "texture file {} (PLY comment TextureFile) not written: an OBJ names its textures in a \
                     material library (.mtl), which delmesh does not write; write PLY to keep it",
                    attributes.texture_files.join(", ")
                ));
            }
            let order = (!face_order.is_empty()).then_some(&face_order[..]);
            copies_of = obj::write_obj_in_order(w, p, triangles, attributes, order)?;
        }
        Format::Ply => {
            let (channels, mut split) = split_per_vertex(attributes, positions.len(), triangles, |_| true);
            // Each property's name and type, and where a written vertex's
            // value comes from: number `k` of its value of channel `c`,
            // times `scale`.
            let mut properties: Vec<(&str, ValueType)> = Vec::new();
            let mut sources: Vec<(usize, usize, f64)> = Vec::new();
            for (c, (kind, channel)) in channels.iter().enumerate() {
                let property = match kind {
                    Kind::Property(i) => attributes.properties.get(*i as usize),
                    _ => None,
                };
                let names: &[&str] = match (kind, property) {
                    (Kind::TexCoord, _) => &["s", "t"],
                    (Kind::Normal, _) => &["nx", "ny", "nz"],
                    (Kind::Color, _) => &["red", "green", "blue", "alpha"],
                    (Kind::Property(_), Some(p)) => &[p.name.as_str()],
                    (Kind::Property(_), None) => &[],
                };
                // Colours are written as bytes from 0..1; an OBJ that wrote
                // them in 0..255 (some do) would be clamped to white.
                let (scale, ty) = match (kind, property) {
                    // A PLY input's float or 16-bit colours keep their type.
                    (Kind::Color, _) => match attributes.color_type {
                        Some(ty @ (ValueType::F32 | ValueType::F64)) => (1.0, ty),
                        Some(ValueType::U16) => (65535.0, ValueType::U16),
                        _ if colors_in_bytes(channel) => {
                            notes.push(COLORS_IN_BYTES.into());
                            (1.0, ValueType::U8)
                        }
                        _ => (255.0, ValueType::U8),
                    },
                    (_, Some(p)) => (1.0, p.ty),
                    _ => (1.0, ValueType::F64),
                };
                // (Texture coordinates of one number get t = 0.)
                let dim = if *kind == Kind::TexCoord {
                    channel.dim.max(2)
                } else {
                    channel.dim
                };
                for (k, &name) in names.iter().enumerate().take(dim) {
                    properties.push((name, ty));
                    sources.push((c, k, scale));
                }
            }
            let face_columns: Vec<PlyColumn> = (attributes.face_properties.iter())
                .map(|p| PlyColumn {
                    name: p.name.clone(),
                    ty: p.ty,
                    values: p.values.clone(),
                })
                .collect();
            // Written vertex `i`'s properties, as the file holds them.
            let put_properties = |split: &PerVertex, i: usize, out: &mut Vec<u8>| {
                for (&(_, ty), &(c, k, scale)) in properties.iter().zip(&sources) {
                    ty.put_le(scale * component(channels[c].1, split.values[c][i], k), out);
                }
            };
            let record = |i: usize| {
                let mut bytes = Vec::new();
                put_properties(&split, i, &mut bytes);
                bytes
            };
            if let Some((to, keep)) = alike_copies(positions.len(), &split, record) {
                drop_copies(&mut split, &to, &keep);
            }
            copies_of = split.source[positions.len()..].to_vec();
            // The texture image with the texture coordinates, as MeshLab names it.
            let comments: Vec<String> = match attributes.texcoords {
                Some(_) => (attributes.texture_files.iter())
                    .map(|name| format!("TextureFile {name}"))
                    .collect(),
                None => Vec::new(),
            };
            // Each vertex's record made as it is written: gathering them in
            // columns first held a copy of every value and position.
            let vertices = formats::VertexRecords {
                count: split.source.len(),
                properties: &properties,
                record: &|i, out: &mut Vec<u8>| {
                    for c in &p[split.source[i] as usize] {
                        out.extend_from_slice(&c.to_le_bytes());
                    }
                    put_properties(&split, i, out);
                },
            };
            formats::write_ply_binary_records(w, p, &split.triangles, &vertices, &face_columns, &comments)?;
        }
        Format::Off => {
            let (channels, split) = split_per_vertex(attributes, positions.len(), triangles, |kind| {
                !matches!(kind, Kind::Property(_))
            });
            let face_colors = off_face_colors(attributes);
            if channels.is_empty() && face_colors.is_none() {
                formats::write_off(w, p, triangles)?;
            } else {
                if attributes.texcoords.is_some() && !attributes.texture_files.is_empty() {
                    notes.push(format!(
                        "texture file {} (PLY comment TextureFile) not written: OFF cannot name a texture; write PLY \
                         to keep it",
                        attributes.texture_files.join(", ")
                    ));
                }
                let mut extras = formats::OffExtras::default();
                for ((kind, channel), index) in channels.iter().zip(&split.values) {
                    // (Texture coordinates of one number get t = 0, of three
                    // lose the third, as in PLY.)
                    let dim = match kind {
                        Kind::TexCoord => 2,
                        _ => channel.dim,
                    };
                    let values = |scale: f64| -> Vec<f64> {
                        (index.iter())
                            .flat_map(|&i| (0..dim).map(move |k| scale * component(channel, i, k)))
                            .collect()
                    };
                    match kind {
                        Kind::TexCoord => extras.texcoords = Some(values(1.0)),
                        Kind::Normal => extras.normals = Some(values(1.0)),
                        Kind::Color => {
                            let (mut text, scale) = off_color_text(attributes.color_type, channel, &mut notes);
                            let mut written = values(scale);
                            // Bytes that are all 0 or 1 would read back as
                            // 0..1 (the OFF reader, as Geomview's, takes whole
                            // numbers for bytes only if one is above 1).
                            let largest = written.iter().fold(0.0f64, |m, &x| m.max(x.round()));
                            if text == formats::ColorText::Bytes && largest == 1.0 {
                                (text, written) = (formats::ColorText::Floats, values(1.0));
                            }
                            extras.colors = Some(formats::OffColors {
                                dim,
                                text,
                                values: written,
                            });
                        }
                        Kind::Property(_) => {}
                    }
                }
                extras.face_colors = face_colors.map(|(held, text)| formats::OffColors {
                    dim: held.len(),
                    text,
                    values: (0..triangles.len())
                        .flat_map(|f| {
                            (held.iter())
                                .map(move |&i| attributes.face_properties[i].values.get(f).copied().unwrap_or(0.0))
                        })
                        .collect(),
                });
                let mut split = split;
                let record = |i: usize| {
                    let mut bytes = Vec::new();
                    let mut numbers = |values: &Option<Vec<f64>>, dim: usize| {
                        if let Some(values) = values {
                            (values[dim * i..dim * (i + 1)].iter())
                                .for_each(|x| bytes.extend(x.to_bits().to_le_bytes()));
                        }
                    };
                    numbers(&extras.texcoords, 2);
                    numbers(&extras.normals, 3);
                    if let Some(c) = &extras.colors {
                        for &x in &c.values[c.dim * i..c.dim * (i + 1)] {
                            match c.text {
                                formats::ColorText::Bytes => bytes.push(formats::color_byte(x)),
                                formats::ColorText::Floats => bytes.extend(x.to_bits().to_le_bytes()),
                            }
                        }
                    }
                    bytes
                };
                if let Some(keep) = merge_alike_copies(positions.len(), &mut split, record) {
                    let pick = |values: &mut Vec<f64>, dim: usize| {
                        let mut kept = Vec::with_capacity(dim * keep.len());
                        keep.iter()
                            .for_each(|&i| kept.extend_from_slice(&values[dim * i..dim * (i + 1)]));
                        *values = kept;
                    };
                    if let Some(t) = &mut extras.texcoords {
                        pick(t, 2);
                    }
                    if let Some(n) = &mut extras.normals {
                        pick(n, 3);
                    }
                    if let Some(c) = &mut extras.colors {
                        pick(&mut c.values, c.dim);
                    }
                }
                let written: Vec<[f64; 3]> = split.source.iter().map(|&v| p[v as usize]).collect();
                copies_of = split.source[positions.len()..].to_vec();
                formats::write_off_with(w, &written, &split.triangles, &extras)?;
            }
        }
        Format::Stl => formats::write_stl_binary(w, p, triangles)?,
    }
    Ok(Written {
        notes,
        copies_of,
        face_order,
    })
}

/// The channels of `attributes` of the kinds `hold` takes that a format
/// storing values per vertex (PLY, OFF) can hold (not those that only some
/// faces have), and the vertices split so that each has one value of each
/// ([`PerVertex`]).
fn split_per_vertex<'a>(
    attributes: &'a Attributes,
    vertices: usize,
    triangles: &[[u32; 3]],
    hold: impl Fn(Kind) -> bool,
) -> (Vec<(Kind, &'a Channel)>, PerVertex) {
    let channels: Vec<_> = (attributes.channels())
        .filter(|&(kind, c)| hold(kind) && !c.is_partial())
        .collect();
    let split = PerVertex::new(
        vertices,
        triangles,
        &channels.iter().map(|(_, c)| *c).collect::<Vec<_>>(),
    );
    (channels, split)
}

/// Drops the copies that `split` made at seams whose record in the file is the same as that
/// of an earlier vertex of the file at the same mesh vertex, and points their corners there:
/// values that differ but are written alike (colours rounded to bytes, numbers narrowed to a
/// property's type) make no seam in the file, and two alike records at one place would read
/// as two vertices, a crack the mesh does not have. `record(i)` is what the file holds for
/// the values of written vertex `i`; the mesh's own `n` vertices stay. Returns the old index
/// of each vertex kept, in order, if any copy was dropped.
fn merge_alike_copies(n: usize, split: &mut PerVertex, record: impl Fn(usize) -> Vec<u8>) -> Option<Vec<usize>> {
    let (to, keep) = alike_copies(n, split, record)?;
    drop_copies(split, &to, &keep);
    Some(keep)
}

/// What [`merge_alike_copies`] would do, `split` left as it is: for each
/// written vertex, the vertex it becomes (new numbering), and the old index
/// of each vertex kept, in order; `None` if no copy would be dropped.
fn alike_copies(n: usize, split: &PerVertex, record: impl Fn(usize) -> Vec<u8>) -> Option<(Vec<u32>, Vec<usize>)> {
    let total = split.source.len();
    if total == n {
        return None;
    }
    // (Mesh vertex, record) -> its first written vertex, new numbering.
    let mut first: crate::hash::FastMap<(u32, Vec<u8>), u32> = Default::default();
    for &v in &split.source[n..] {
        first.entry((v, record(v as usize))).or_insert(v);
    }
    let mut to: Vec<u32> = (0..n as u32).collect();
    let mut keep: Vec<usize> = (0..n).collect();
    for i in n..total {
        let next = keep.len() as u32;
        let target = *first.entry((split.source[i], record(i))).or_insert(next);
        if target == next {
            keep.push(i);
        }
        to.push(target);
    }
    (keep.len() < total).then_some((to, keep))
}

/// Drops the copies [`alike_copies`] found (`to`, `keep`) from `split`.
fn drop_copies(split: &mut PerVertex, to: &[u32], keep: &[usize]) {
    split.triangles.iter_mut().flatten().for_each(|v| *v = to[*v as usize]);
    split.source = keep.iter().map(|&i| split.source[i]).collect();
    for column in &mut split.values {
        *column = keep.iter().map(|&i| column[i]).collect();
    }
}

/// Number `k` of value `i` of `channel` (0 where it has none).
fn component(channel: &Channel, i: u32, k: usize) -> f64 {
    channel.value(i).get(k).copied().unwrap_or(0.0)
}

/// The note on colours written as [`colors_in_bytes`] says.
const COLORS_IN_BYTES: &str = "colours above 1 taken as 0-255 (the file's scale), written as they are";

/// How an OFF output writes `colors` of `color_type`
/// ([`Attributes::color_type`]), and the factor they are written with:
/// 8-bit ones (an integer type but `ushort`, as an OFF input's whole
/// numbers are typed) as bytes, as most COFF files hold them; colours in
/// 0..255 ([`colors_in_bytes`]) as they are, rounded, with a note; others
/// (an OBJ's, an OFF's floats, a PLY's `float`, `double` or `ushort` ones)
/// as numbers in shortest round-trip form.
fn off_color_text(
    color_type: Option<ValueType>,
    colors: &Channel,
    notes: &mut Vec<String>,
) -> (formats::ColorText, f64) {
    match color_type {
        Some(ty) if ty.is_integer() && ty != ValueType::U16 => (formats::ColorText::Bytes, 255.0),
        _ if colors_in_bytes(colors) => {
            notes.push(COLORS_IN_BYTES.into());
            (formats::ColorText::Bytes, 1.0)
        }
        _ => (formats::ColorText::Floats, 1.0),
    }
}

/// What [`write_mesh_with_attributes`] wrote besides the mesh's own vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Written {
    /// A note for each attribute the format could not hold.
    pub notes: Vec<String>,
    /// The file's vertices after the mesh's own (which come first, in
    /// order): copies at attribute seams, as PLY and OFF write a vertex once
    /// per value, and OBJ once per colour; each entry is the mesh vertex the
    /// copy repeats. Empty for STL and where no vertex has several values.
    pub copies_of: Vec<u32>,
    /// The mesh triangle each face of the file is, in the file's order,
    /// where that is not the mesh's own order (an OBJ writes its faces
    /// group by group: [`obj::faces_in_file_order`]); empty otherwise.
    pub face_order: Vec<u32>,
}

/// Whether a colour channel holds values in 0..255 rather than 0..1: one
/// above 1 at least, none negative or above 255 (OBJ has no rule, and some
/// exporters write bytes).
fn colors_in_bytes(channel: &Channel) -> bool {
    let (lo, hi) = (channel.values.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
        (lo.min(x), hi.max(x))
    });
    hi > 1.0 && hi <= 255.0 && lo >= 0.0
}

/// Writes a triangle mesh as OBJ, atomically.
pub fn write_obj(path: &Path, positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<()> {
    write_atomic(path, |w| obj::write_obj(w, bytemuck_positions(positions), triangles))
}

/// Writes OBJ text to any writer.
pub fn write_obj_to(w: &mut dyn Write, positions: &[DVec3], triangles: &[[u32; 3]]) -> std::io::Result<()> {
    obj::write_obj(w, bytemuck_positions(positions), triangles)
}

/// Views positions as plain arrays without copying.
fn bytemuck_positions(p: &[DVec3]) -> &[[f64; 3]] {
    bytemuck::cast_slice(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<InputMesh> {
        parse_obj(text.as_bytes(), Path::new("t.obj"))
    }

    #[test]
    fn writes_shortest_round_trip_floats() {
        let p = vec![
            DVec3::new(0.1, -0.0, 1e-300),
            DVec3::new(1.0 / 3.0, 2.5, 1e22),
            DVec3::new(7.0, 8.0, 9.0),
        ];
        let mut out = Vec::new();
        write_obj_to(&mut out, &p, &[[0, 1, 2]]).unwrap();
        let text = String::from_utf8(out).unwrap();
        let back = parse(&text).unwrap();
        assert_eq!(back.positions, p);
        assert!(text.starts_with("v 0.1 -0.0 1e-300\n"), "{text}");
        assert!(text.ends_with("f 1 2 3\n"));
    }

    #[test]
    fn every_output_format_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let p = vec![
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0 / 3.0),
        ];
        for ext in ["obj", "off", "ply", "stl"] {
            let path = dir.path().join(format!("m.{ext}"));
            write_mesh(&path, &p, &[[0, 1, 2]]).unwrap();
            let back = read_obj(&path).unwrap();
            assert_eq!(back.triangles.len(), 1, "{ext}");
            if ext != "stl" {
                assert_eq!(back.positions, p, "{ext}");
            }
        }
    }
}
