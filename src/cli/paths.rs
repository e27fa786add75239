//! Which files a run may read and write: the output folder, the same file under
//! two names, the printout into an input, and material libraries named relative
//! to the output.

use super::*;

/// Makes the `mtllib` statements of an OBJ written to `output` name the
/// material libraries of `input` (read from its folder) from the output's
/// folder: a relative name (`mat.mtl`) is rewritten as the path from there
/// (`../models/mat.mtl`) when the two folders differ and the library is
/// beside the input, so that viewers still find it (and its textures,
/// named from the library's own folder). A statement is one name if that
/// name is a file beside the input (names with blanks, as Blender writes
/// them), else names separated by blanks. Returns the notes saying what
/// was rewritten, or why a name could not be (a path with blanks).
pub(super) fn rebase_material_libraries(mtllib: &mut [String], input: &Path, output: &Path) -> Vec<String> {
    let mut notes = Vec::new();
    if mtllib.is_empty() || io::is_standard_input(input) || io::is_stream(output) {
        return notes;
    }
    let folder = |p: &Path| -> Option<PathBuf> {
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::canonicalize(dir).ok()
    };
    let (Some(from), Some(to)) = (
        folder(input),
        io::write_target(output).ok().and_then(|(target, _)| folder(&target)),
    ) else {
        return notes;
    };
    if from == to {
        return notes;
    }
    let up = relative_path(&to, &from);
    for statement in mtllib.iter_mut() {
        let names: Vec<&str> = if from.join(statement.as_str()).is_file() {
            vec![statement.as_str()]
        } else {
            statement.split_whitespace().collect()
        };
        let mut rebased = Vec::with_capacity(names.len());
        let mut changed = false;
        for name in names {
            let beside_input = from.join(name);
            let same_file = std::fs::canonicalize(to.join(name)).ok() == std::fs::canonicalize(&beside_input).ok();
            if Path::new(name).is_absolute() || !beside_input.is_file() || same_file {
                rebased.push(name.to_owned());
                continue;
            }
            let path = up.join(name).to_string_lossy().into_owned();
            if path.contains(char::is_whitespace) {
                notes.push(format!(
                    "mtllib {name}: the material library is beside the input and its path from the output's \
                     folder has blanks, which OBJ readers split at: copy it beside the output"
                ));
                rebased.push(name.to_owned());
                continue;
            }
            notes.push(format!(
                "mtllib {name} written as {path}: the path from the output's folder to the input's material library"
            ));
            rebased.push(path);
            changed = true;
        }
        if changed {
            *statement = rebased.join(" ");
        }
    }
    notes
}

/// The relative path from the folder `from` to the folder `to` (both
/// absolute, canonical): `..` for each of `from`'s own components, then
/// `to`'s own.
fn relative_path(from: &Path, to: &Path) -> PathBuf {
    let common = from
        .components()
        .zip(to.components())
        .take_while(|(a, b)| a == b)
        .count();
    let mut path = PathBuf::new();
    for _ in from.components().skip(common) {
        path.push("..");
    }
    for part in to.components().skip(common) {
        path.push(part);
    }
    path
}

/// Refuses an output path that cannot be written, before any work starts.
/// A device or pipe (`/dev/null`, `/dev/stdout`) is written into directly
/// ([`io::write_atomic`]) and needs no folder.
pub(super) fn check_output_dir(path: &Path) -> anyhow::Result<()> {
    if io::is_stream(path) {
        return Ok(());
    }
    if names_folder(path) && !path.is_dir() {
        bail!(
            "{}: output names a folder (its name ends in /), not a file",
            path.display()
        );
    }
    let (_, dir) = io::write_target(path).map_err(|source| delmesh::Error::Write {
        path: path.to_owned(),
        source,
    })?;
    let dir = dir.as_path();
    if !dir.is_dir() {
        bail!("{}: output folder {} does not exist", path.display(), dir.display());
    }
    if path.is_dir() {
        bail!("{}: output is a folder, not a file", path.display());
    }
    // Writable? Probe with the same kind of temporary file the atomic write uses.
    if let Err(e) = io::temporary::TempFile::create_in(dir, ".delmesh-", ".tmp") {
        bail!("{}: cannot write in folder {}: {e}", path.display(), dir.display());
    }
    Ok(())
}

/// Whether `path` can only name a folder: its last part is empty (it ends
/// in `/`), `.` or `..`.
fn names_folder(path: &Path) -> bool {
    let bytes = path.as_os_str().as_encoded_bytes();
    let last = bytes.rsplit(|&b| b == b'/').next().unwrap_or_default();
    matches!(last, b"" | b"." | b"..")
}

/// The file `p` names, comparable between paths: symbolic links and `..`
/// resolved, also for a file that does not exist yet (its folder then
/// must). `None` if neither resolves.
pub(super) fn file_key(p: &Path) -> Option<PathBuf> {
    std::fs::canonicalize(p).ok().or_else(|| {
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(std::fs::canonicalize(dir).ok()?.join(p.file_name()?))
    })
}

/// Refuses two of the files a run writes (`written`: what, path) that are
/// one file, which the second written would replace, and any that is the
/// input, except `written[i]` for `in_place` = `Some(i)` (the output of a
/// run without -o). The input is also the file standard input is
/// redirected from, for `-`, and a file is also itself under another name
/// (`/dev/stdin`, `/dev/fd/3`, a hard link: the same device and inode), so
/// `delmesh -i - -o /dev/stdin < m.obj` and `-o - >> m.obj` are refused.
/// Devices and pipes (`/dev/null`, `/dev/stdout` on a terminal) may be
/// named more than once.
pub(super) fn refuse_same_files(
    input: &Path,
    in_place: Option<usize>,
    written: &[(String, PathBuf)],
) -> anyhow::Result<()> {
    let input_key = if io::is_standard_input(input) {
        None
    } else {
        file_key(input)
    };
    let input_id = io::FileId::of_input(input);
    for (i, (what, path)) in written.iter().enumerate() {
        let Some(fd) = io::standard_stream(path) else { continue };
        if let Some((other, _)) = written[..i].iter().find(|(_, p)| io::standard_stream(p) == Some(fd)) {
            let stream = if fd == 1 { "standard output" } else { "standard error" };
            bail!("{}: {what} and {other} would both go to {stream}", path.display());
        }
        if input_id.is_some() && io::FileId::of_standard(fd) == input_id {
            let stream = if fd == 1 { "standard output" } else { "standard error" };
            bail!(
                "{}: input file is output file: {what} would go to {stream}, which is the input",
                input.display()
            );
        }
    }
    let keys: Vec<Option<PathBuf>> = written
        .iter()
        .map(|(_, p)| if io::is_stream(p) { None } else { file_key(p) })
        .collect();
    for (i, (what, path)) in written.iter().enumerate() {
        let is_input = || {
            (keys[i].is_some() && keys[i] == input_key)
                || (input_id.is_some() && io::standard_stream(path).is_none() && io::FileId::of_path(path) == input_id)
        };
        if in_place != Some(i) && is_input() {
            // (Rewriting the input is what a run without -o does, after
            // the checks that make it safe: say so.)
            let hint = if what == "the output" && !io::is_standard_input(input) {
                ": leave out -o to rewrite the input in place"
            } else {
                ""
            };
            bail!("{}: {what} would overwrite the input{hint}", path.display());
        }
        let Some(key) = &keys[i] else { continue };
        if let Some(j) = keys[..i].iter().position(|k| k.as_ref() == Some(key)) {
            bail!("{}: {what} and {} name the same file", path.display(), written[j].0);
        }
    }
    Ok(())
}

/// Refuses a run whose printout would go into one of its `inputs` (a
/// regular file standard output is appended to: `delmesh -i m.obj -o
/// out.obj >> m.obj`), as `cat` refuses; `quiet` prints nothing. (An
/// output file on standard output is refused by [`refuse_same_files`].)
pub(super) fn refuse_printout_into_inputs(inputs: &[&Path], quiet: bool) -> anyhow::Result<()> {
    if quiet || PRINTOUT_TO_STDERR.load(std::sync::atomic::Ordering::Relaxed) {
        return Ok(());
    }
    let Some(stdout) = io::FileId::of_standard(1) else {
        return Ok(());
    };
    if let Some(input) = inputs.iter().find(|p| io::FileId::of_input(p) == Some(stdout)) {
        bail!(
            "{}: input file is output file: the printout would go to standard output, which is this input",
            input.display()
        );
    }
    Ok(())
}
