//! Reading and writing meshes.
//!
//! Formats: OBJ (delmesh's own reader, [`obj`]), OFF, PLY (ASCII and binary,
//! either endianness) and STL (ASCII and binary) ([`formats`]), chosen by the
//! file's extension or, where that says nothing, by its content; any of them
//! may be gzip-compressed. Every reader produces a [`RawMesh`] of polygons;
//! [`finish`] turns it into the [`InputMesh`] the algorithm takes: polygons
//! fan-triangulated (from the first corner that sees the whole polygon:
//! [`polygon`]), identical positions welded (-0 and 0 alike), unused vertices dropped,
//! and every refusal of SPEC §6 naming the file and the offending line, face
//! or vertex. With `--repair` ([`crate::repair`]) the refusable defects are
//! fixed instead.
//!
//! Writing is atomic: a temporary file in the target's directory, renamed
//! over the target only once it is complete.
//!
//! Here the module's public face; reading, welding and building the surface
//! are in `read.rs`, writing each format with its attributes in `write.rs`,
//! staging and atomic replacement in `atomic.rs`.

pub mod formats;
pub mod number;
pub mod obj;
pub mod polygon;
pub mod temporary;

mod atomic;
mod lines;
mod read;
mod write;

pub use atomic::{
    is_standard_input, is_stream, set_sync_writes, split_extensions, stage, standard_stream, write_atomic,
    write_target, FileId, Staged,
};
pub(crate) use lines::push_decimal;
pub(crate) use read::short_edge_text;
pub use read::{
    build_surface, build_surface_with, detect_format, edges_in_supported_scale, finish, in_supported_range, parse_obj,
    read_bytes, read_mesh, read_obj, read_raw, InputMesh, ReadOptions, MAX_COORDINATE, MIN_EDGE,
};
pub use write::{
    drop_attributes_format_cannot_hold, output_format, stage_mesh_after, stage_mesh_with_attributes, write_mesh,
    write_mesh_after, write_mesh_with_attributes, write_obj, write_obj_to, written_with_attributes, Written,
};

pub use formats::{Format, FormatError, Numbering, OriginKind, PlyColumn, RawMesh};
pub use lines::VertexLines;
