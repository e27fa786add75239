//! `delmesh render`: a picture of a mesh, its non-Delaunay edges and (given the
//! input) its added vertices.

use super::*;

/// `delmesh render MESH -o PICTURE [--input INPUT]`: draws `mesh` seen from
/// `view` as SVG or PNG (by the picture's name), its non-Delaunay edges red
/// and, given the `input` it was made from, its added vertices blue; never
/// over a mesh file.
pub(super) fn run_render(
    mesh: &Path,
    output: &Path,
    input: Option<&Path>,
    view: delmesh::render::View,
) -> anyhow::Result<ExitCode> {
    if mesh == Path::new("-") && input == Some(Path::new("-")) {
        bail!("MESH and --input are both standard input: at most one of them can be `-`");
    }
    check_output_dir(output)?;
    // A picture never replaces a mesh: neither one it reads nor, by a slip
    // of the name, any other.
    let picture = [("the picture".to_string(), output.to_path_buf())];
    for read in std::iter::once(mesh).chain(input) {
        refuse_same_files(read, None, &picture)?;
    }
    // A picture on standard output is alone there.
    if io::standard_stream(output) == Some(1) {
        PRINTOUT_TO_STDERR.store(true, std::sync::atomic::Ordering::Relaxed);
    }
    refuse_printout_into_inputs(&[mesh, input.unwrap_or(mesh)], false)?;
    refuse_closed_stdout(true)?;
    crate::working_on(mesh);
    let name = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if io::formats::format_from_name(&name).is_some() {
        bail!(
            "{}: render writes a picture (SVG, or PNG for a .png name), not a mesh: name it .svg or .png",
            output.display()
        );
    }
    let format = Format::of_picture(output, &output.display().to_string()).map_err(anyhow::Error::msg)?;
    let m = io::read_mesh(mesh, &io::ReadOptions::default())?;
    let original = input
        .map(|p| io::read_mesh(p, &io::ReadOptions::default()))
        .transpose()?;
    let (canvas, drawn) = delmesh::render::render(
        &m.positions,
        &m.triangles,
        original.as_ref().map(|o| &o.positions[..]),
        &view,
    );
    let bytes = canvas.encode(format).with_context(|| output.display().to_string())?;
    io::write_atomic(output, |w| w.write_all(&bytes))?;
    say!(
        "render  {}: {} drawn, {} (red), {} (blue)",
        output.display(),
        count(drawn.faces, "face", "faces"),
        count(drawn.non_delaunay_edges, "non-Delaunay edge", "non-Delaunay edges"),
        count(drawn.added_vertices, "added vertex", "added vertices")
    );
    // Every input vertex is in a mesh made from it; if not, "added" means
    // nothing (every vertex of an unrelated mesh is blue).
    if let (Some(original), Some(input)) = (&original, input) {
        let in_mesh: std::collections::HashSet<[u64; 3]> = m
            .positions
            .iter()
            .map(|p| delmesh::hash::position_key(p.to_array()))
            .collect();
        let missing = (original.positions.iter())
            .filter(|p| !in_mesh.contains(&delmesh::hash::position_key(p.to_array())))
            .count();
        if missing > 0 {
            say!(
                "note    {} of the {} vertices of {} are not in {}: is it the mesh {} was made from?",
                missing,
                original.positions.len(),
                input.display(),
                mesh.display(),
                mesh.display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
