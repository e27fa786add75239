//! The command line's arguments (clap): the main command's flags, the
//! subcommands, and how the report's single-dash flags are read.

use super::*;

/// Turn a triangle mesh into a Delaunay mesh with exactly the same geometry.
///
/// Reads an OBJ, splits input edges at sample points and flips edges inside
/// flat regions until every interior edge is Delaunay (its two opposite
/// angles sum to at most pi), and writes an OBJ whose first vertices are the
/// input's, bit for bit. Texture coordinates, normals, colours, groups,
/// materials, smoothing groups and PLY vertex and face properties are carried, with the
/// texture mapping unchanged (see --drop-attributes). The report's single-dash flags (-ds, -nomedian,
/// -all) work as written; each has a GNU-style long form.
#[derive(Parser, Debug)]
#[command(
    name = "delmesh",
    version,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
#[command(after_help = "Examples:\n  \
    delmesh -i bunny.obj -o out/bunny.obj                 (stack, score 2, median: the report's best)\n  \
    delmesh -i elephant2.obj -o output/elephant.obj -s 2 -ds pqueue\n  \
    delmesh -i elephant2.obj -o output/elephant.obj -all  (all 18 combinations)\n  \
    delmesh check bunny.obj out/bunny.obj                 (verify an output)")]
pub(super) struct Cli {
    #[command(subcommand)]
    pub(super) command: Option<Command>,
    #[command(flatten)]
    pub(super) run: RunArgs,
}

#[derive(clap::Args, Debug)]
pub(super) struct RunArgs {
    /// Input mesh: OBJ, OFF, PLY or STL, by extension or content, possibly
    /// gzip-compressed (.gz). `-` reads standard input (format by content).
    #[arg(short = 'i', long = "input", value_name = "FILE", required = true)]
    pub(super) input: Option<PathBuf>,

    /// Output mesh: OBJ, OFF or PLY (binary) by extension, OBJ if none (or
    /// another, with a note saying so); gzip-compressed if the name ends in
    /// .gz; STL only with --no-refine (its f32 coordinates cannot hold a
    /// refined mesh). `-` writes OBJ to
    /// standard output, and the printout then goes to standard error. A
    /// device or pipe (/dev/null, /dev/stdout) is written into. Without it
    /// the input file is rewritten, only after success (standard input's
    /// mesh goes to standard output). With -all, the stem, folder and
    /// extension of the 18 output files.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub(super) output: Option<PathBuf>,

    #[command(flatten)]
    pub(super) settings: Settings,

    /// Run all 18 combinations (3 DS x 3 scores x median on/off), writing
    /// <stem>-<s|q|p>-<0|1|2>[-m].obj beside the output and printing a
    /// summary table; -ds, -s and -nomedian are ignored [legacy: -all].
    #[arg(long = "all")]
    pub(super) all: bool,

    /// With -all: also sweep delmesh's score 3 (6 more runs, 24 in all,
    /// named <stem>-<s|q|p>-3[-m].obj). Add --prune to sweep pruning.
    #[arg(long = "extended", requires = "all")]
    pub(super) extended: bool,

    /// With --repair: also write the repaired input here, the mesh `delmesh
    /// check` should compare the output with (positions and faces only;
    /// `--repair --no-refine -o FILE` writes it with its attributes).
    #[arg(long = "repaired", value_name = "FILE", requires = "repair")]
    pub(super) repaired: Option<PathBuf>,

    /// How many threads to use (default: one per core): with -all and
    /// --smallest, how many runs at once; otherwise for the passes over all
    /// edges, for reading a big OBJ or ASCII PLY and for formatting the output. Results
    /// never depend on it.
    #[arg(short = 'j', long = "jobs", value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u16).range(1..))]
    pub(super) jobs: Option<u16>,

    /// Also write every figure of the run (with -all: of every combination),
    /// the sample constants, seconds per phase and peak memory, as JSON.
    #[arg(long = "stats-json", value_name = "FILE")]
    pub(super) stats_json: Option<PathBuf>,

    /// Also write the figures of each run (18 rows with -all) as CSV, one
    /// row per run, with the column names of the JSON run records.
    #[arg(long = "stats-csv", visible_alias = "sweep-csv", value_name = "FILE")]
    pub(super) stats_csv: Option<PathBuf>,

    /// With -all: draw the added vertices of every combination as a bar
    /// chart, in the table's order (SVG, or PNG for a .png name).
    #[arg(long = "chart", value_name = "FILE", requires = "all")]
    pub(super) chart: Option<PathBuf>,

    /// Progress line on stderr (phase, counts, seconds) for work longer than
    /// about a second: auto draws it only when stderr is a terminal; -q
    /// turns it off.
    #[arg(long = "progress", value_enum, default_value = "auto", value_name = "WHEN")]
    pub(super) progress: progress::When,

    /// Only read (and repair) and write: no refinement, the output is NOT made
    /// Delaunay. For format conversion, repair alone, and measuring the I/O
    /// floor.
    #[arg(long = "no-refine", conflicts_with = "all")]
    pub(super) no_refine: bool,

    /// Fewest added vertices: run 24 settings (3 DS x scores 0-3 with the
    /// median, 3 DS x scores 2 and 4 with --shells, 3 DS x scores 2-3
    /// without the median) on all cores (or -j), prune those that added at
    /// most 4 times the fewest vertices plus 1000, and write the smallest
    /// result (ties: the first in that order); -ds, -s, -nomedian and
    /// --shells are ignored.
    #[arg(long = "smallest", conflicts_with_all = ["all", "no_refine"])]
    pub(super) smallest: bool,

    /// Also write where each output vertex comes from, as CSV
    /// (output_index,input_index_a,input_index_b,t; 0-based, input indices
    /// in the input file's numbering, an STL's corner k of facet f being
    /// 3f + k): its position is exactly a + t(b - a) in f64; input vertices
    /// are a,a,0. For carrying per-vertex data over.
    #[arg(long = "vertex-map", value_name = "FILE", conflicts_with = "all")]
    pub(super) vertex_map: Option<PathBuf>,

    /// Also write which input face each output face lies in, as CSV
    /// (output_index,input_index,inside; 0-based, in the input file's
    /// numbering of faces, a polygon being one face): inside is 1 when that
    /// face holds the output face whole, 0 for a face that a flip in a flat
    /// region laid across several input faces (the row then names the one
    /// under its centroid). For carrying per-face data over.
    #[arg(long = "face-map", value_name = "FILE", conflicts_with = "all")]
    pub(super) face_map: Option<PathBuf>,

    /// Verify the output with `delmesh check` once written (against the
    /// input, or with --repair the repaired input), before it is put in
    /// place; if it fails (or the check cannot read it), it is put at
    /// OUTPUT.rejected instead and the exit status is 1 (without -o the
    /// input is then kept as it was). With -all, every file, each as soon
    /// as it is written.
    #[arg(long = "check", conflicts_with = "no_refine")]
    pub(super) check: bool,

    /// Print nothing but errors.
    #[arg(short = 'q', long = "quiet")]
    pub(super) quiet: bool,
}

/// The settings a refinement takes, shared by the main command and `batch`.
#[derive(clap::Args, Debug)]
pub(super) struct Settings {
    /// Data structure holding the non-Delaunay edges [legacy: -ds].
    #[arg(
        long = "ds",
        visible_alias = "data-structure",
        value_enum,
        default_value = "stack",
        value_name = "DS"
    )]
    pub(super) ds: DsArg,

    /// Score of a sample: 0 all equal (the paper's), 1 weighted center,
    /// 2 always center (the report's), 3 split-aware (delmesh's: as 2, but
    /// outer edges that can be flipped cost nothing), 4 uniform (delmesh's:
    /// every sample equal, so the median or --shells alone decides).
    #[arg(short = 's', long = "score", default_value = "2", allow_negative_numbers = true, value_parser = ["0", "1", "2", "3", "4"], value_name = "N")]
    pub(super) score: String,

    /// Take the first best sample from the edge's start instead of the median
    /// of the best ones [legacy: -nomedian].
    #[arg(long = "nomedian", visible_alias = "no-median")]
    pub(super) nomedian: bool,

    /// Among the best samples take the one nearest a concentric shell
    /// around the sub-edge's input vertex (rho_v * 2^k from it) instead of
    /// the median: the edges around a vertex are then split at the same
    /// distances, which keeps fans and cone tips Delaunay (CAD parts).
    #[arg(long = "shells", conflicts_with = "nomedian")]
    pub(super) shells: bool,

    /// Also make every boundary edge Gabriel: the one angle opposite it at
    /// most pi/2, so that its cotangent weight is not negative, by splitting
    /// the boundary edges that face an obtuse angle. With it, every weight of
    /// the output's cotangent Laplacian is non-negative, on open meshes too
    /// (without it boundary edges count as Delaunay, as in the report)
    #[arg(long = "gabriel-boundary")]
    pub(super) gabriel_boundary: bool,

    /// Work limit: stop (exit 1) when a run needs more than this many added
    /// vertices, or more than three times as many flips; `Nx` (such as
    /// `20x`): N times the input's vertex count, file by file in `batch`.
    /// Some settings (the first best sample instead of the median, on
    /// inputs with tiny angles) would otherwise add billions of vertices or
    /// flip quadratically often. With -all and --smallest, each of their
    /// runs.
    #[arg(long = "max-added", value_name = "N", default_value = "10000000", allow_negative_numbers = true, value_parser = work_limit)]
    pub(super) max_added: WorkLimit,

    /// Make every flip Algorithm 2's, in the --ds order to the end, as the
    /// report's tool did. Without it, large flat regions far from Delaunay
    /// are first made Delaunay directly: a convex polygon of 256 corners or
    /// more (an oval cap fanned from one corner) by fewer than 2 flips per
    /// corner, any other region of 256 vertices or more on which flips would
    /// take over 8 per vertex (a strip, a non-convex cap cut into ears) by
    /// rebuilding it as its constrained Delaunay triangulation; and a stack
    /// or queue run that has flipped more than 8 times per edge of the mesh
    /// takes the rest longest edge first. Each says so: the stack would flip
    /// such regions quadratically often.
    #[arg(long = "keep-order")]
    pub(super) keep_order: bool,

    /// Fix what would be refused: weld positions (see --weld-tolerance),
    /// drop faces that repeat a vertex, zero-area and duplicate faces, orient
    /// each component consistently, cut non-manifold edges and vertices apart.
    /// Prints one line per kind of fix.
    #[arg(long = "repair")]
    pub(super) repair: bool,

    /// With --repair: weld vertices closer than this distance (0: only
    /// identical positions, -0 and 0 alike).
    #[arg(
        long = "weld-tolerance",
        value_name = "DIST",
        default_value_t = 0.0,
        requires = "repair",
        allow_negative_numbers = true,
        value_parser = weld_distance
    )]
    pub(super) weld_tolerance: f64,

    /// Flush every file written to the disk before renaming it into place,
    /// so that it survives a power loss too (writes are atomic either way).
    #[arg(long = "sync")]
    pub(super) sync: bool,

    /// After the construction, remove again every added vertex whose removal
    /// (with flips around it) keeps the mesh Delaunay. Fewer added vertices,
    /// same exact geometry; with -all, every combination is pruned.
    #[arg(long = "prune")]
    pub(super) prune: bool,

    /// Prune (implies --prune) in at most N passes over the added vertices
    /// (1-8; without it, until a pass removes nothing, at most 8). On big
    /// meshes one pass removes most of what pruning can in a fraction of
    /// its time.
    #[arg(long = "prune-passes", value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u8).range(1..=8))]
    pub(super) prune_passes: Option<u8>,

    /// Ignore the input's texture coordinates, normals, colours, groups,
    /// materials, smoothing groups and PLY vertex and face properties: write positions only, and let planar regions ignore seams
    /// (they are kept by default, and regions cut where a flip would
    /// distort them).
    #[arg(long = "drop-attributes")]
    pub(super) drop_attributes: bool,

    /// How far a flat region's texture coordinates, normals, colours and
    /// other PLY vertex properties may lie from one affine field (relative
    /// to each attribute's largest magnitude in the region's object) for
    /// the region to be flipped as a whole, as without them: their fields
    /// then move by at most twice this there, and a note says how far.
    /// Rounded values, as exporters write them, are rarely affine exactly;
    /// with 0 (exact) the thin fan triangles of a textured flat polygon
    /// written as triangles get split instead of flipped (a polygon of the
    /// file is flipped inside at any tolerance, its corners keeping their
    /// values). One number sets all; `texcoords=REL`,
    /// `normals=REL`, `colors=REL`, `properties=REL` (comma separated) set
    /// some, the others keep their defaults. Default: 1e-5 for texture
    /// coordinates and vertex properties, 1e-3 for normals, 4e-3 for
    /// colours (about an 8-bit step)
    #[arg(long = "attribute-tolerance", value_name = "REL", allow_negative_numbers = true, value_parser = attribute_tolerances)]
    pub(super) attribute_tolerance: Option<Tolerances>,
}

impl Settings {
    /// The passes pruning may take (`None`: no pruning).
    pub(super) fn prune(&self) -> Option<usize> {
        match self.prune_passes {
            Some(n) => Some(usize::from(n)),
            None => self.prune.then_some(delmesh::prune::MAX_PASSES),
        }
    }

    /// The refinement's options: DS, score, median rule and the work limit
    /// for an input of `input_vertices` vertices.
    pub(super) fn options(&self, input_vertices: usize) -> Options {
        let mut options = Options::new(self.ds.into(), score_of(&self.score), !self.nomedian);
        options.shells = self.shells;
        options.max_added = self.max_added.for_input(input_vertices);
        options.keep_order = self.keep_order;
        options
    }

    /// How closely attributes must be affine for a flat region to be
    /// flipped as a whole (`--attribute-tolerance`).
    pub(super) fn tolerances(&self) -> Tolerances {
        self.attribute_tolerance.unwrap_or_default()
    }

    /// Builds the refinable mesh of `input`, read from `path`.
    /// (With --gabriel-boundary, boundary edges are tested too.)
    pub(super) fn build(&self, input: &mut io::InputMesh, path: &Path) -> delmesh::Result<Surface> {
        let mut surface = io::build_surface_with(input, path, self.tolerances())?;
        surface.gabriel_boundary = self.gabriel_boundary;
        Ok(surface)
    }

    /// Reads `path`, with or without repair, and without its attributes
    /// under --drop-attributes, or those that `output`'s format cannot hold
    /// (with a note): they would cost splits and not be written.
    /// `refining`: false under --no-refine; `face_numbers`: with a face
    /// map to write ([`io::ReadOptions::face_numbers`]).
    pub(super) fn read(
        &self,
        path: &Path,
        output: &Path,
        refining: bool,
        face_numbers: bool,
    ) -> anyhow::Result<io::InputMesh> {
        let options = io::ReadOptions {
            repair: self.repair.then_some(delmesh::repair::RepairOptions {
                weld_tolerance: self.weld_tolerance,
            }),
            drop_attributes: self.drop_attributes,
            face_numbers,
        };
        let mut input = io::read_mesh(path, &options)?;
        if let Some(note) = io::drop_attributes_format_cannot_hold(&mut input, io::output_format(output), refining) {
            input.notes.push(note);
        }
        Ok(input)
    }
}

#[derive(Subcommand, Debug)]
pub(super) enum Command {
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell)
    /// to standard output.
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff) to standard output.
    Man,
    /// Draw MESH as SVG or PNG: non-Delaunay edges in red; with --input,
    /// the vertices MESH adds to it (and their edges) in blue.
    Render {
        /// The mesh to draw.
        mesh: PathBuf,
        /// The picture to write: PNG for a .png name, SVG otherwise (never a
        /// mesh name, MESH or the --input file).
        #[arg(short = 'o', long = "output", value_name = "FILE")]
        output: PathBuf,
        /// The original mesh, to mark added vertices.
        #[arg(short = 'i', long = "input", value_name = "FILE")]
        input: Option<PathBuf>,
        /// View direction: degrees around the vertical axis.
        #[arg(long, default_value_t = 30.0, allow_negative_numbers = true, value_parser = finite_degrees)]
        azimuth: f64,
        /// View direction: degrees above the horizon, -90 to 90.
        #[arg(long, default_value_t = 20.0, allow_negative_numbers = true, value_parser = elevation_degrees)]
        elevation: f64,
        /// Picture width and height in pixels.
        #[arg(long, default_value_t = 800, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(16..=8192))]
        size: u32,
    },
    /// Refine many meshes in one process, several at once: each INPUT is
    /// written to the --out-dir folder under its own name, exactly as the
    /// main command would write it. One line per file; exits 1 if any failed.
    Batch(batch::BatchArgs),
    /// Verify that OUTPUT is a Delaunay mesh with the geometry of INPUT,
    /// reading the two files only (and the maps given, with the file they
    /// number). Exits 0 if it is (and they are right), 1 if not.
    Check {
        /// The original mesh (`-`: standard input).
        input: PathBuf,
        /// The mesh to verify (`-`: standard input, e.g. piped from `delmesh -o -`).
        output: PathBuf,
        /// How many threads to use (default: one per core; two are used, to
        /// read the files and run the independent rules side by side on
        /// large meshes). `-j 1` when running many checks at once. The
        /// report never depends on it.
        #[arg(short = 'j', long = "jobs", value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u16).range(1..))]
        jobs: Option<u16>,
        /// Also verify the vertex map the run wrote (`--vertex-map`): every
        /// output vertex rebuilt bit for bit from its row.
        #[arg(long = "vertex-map", value_name = "FILE")]
        vertex_map: Option<PathBuf>,
        /// Also verify the face map the run wrote (`--face-map`): every
        /// output face on the input face its row names.
        #[arg(long = "face-map", value_name = "FILE")]
        face_map: Option<PathBuf>,
        /// The file the run read, which the maps number, when INPUT is
        /// another (the `--repaired` file of a run with `--repair`).
        #[arg(long = "original", value_name = "FILE")]
        original: Option<PathBuf>,
        /// The run's --weld-tolerance, if it gave one: the face map's input
        /// faces are judged where that weld moved them.
        #[arg(long = "weld-tolerance", value_name = "DIST", default_value_t = 0.0, allow_negative_numbers = true, value_parser = weld_distance)]
        weld_tolerance: f64,
        /// Print nothing when it passes; when it fails, only the FAIL and
        /// FAILED lines (and the notes that say why). The exit status is
        /// the same.
        #[arg(short = 'q', long = "quiet")]
        quiet: bool,
        /// Also require every boundary edge to be Gabriel (its one opposite
        /// angle at most pi/2 + 1e-9 rad: a non-negative cotangent weight),
        /// as `--gabriel-boundary` makes them, and print how far they are.
        #[arg(long = "gabriel-boundary")]
        gabriel_boundary: bool,
        /// Also write the verdict as JSON to FILE (`-`: standard output, the
        /// printout then going to standard error): the counts, every failure
        /// line and how many failures of each kind, the maps' verdicts
        /// (fields listed in README.md). Written atomically whenever the
        /// files could be judged, passing or not; not when one cannot be
        /// read.
        #[arg(long = "json", value_name = "FILE")]
        json: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub(super) enum DsArg {
    /// Last in, first out.
    Stack,
    /// First in, first out.
    Queue,
    /// Longest edge first.
    Pqueue,
}

impl From<DsArg> for Worklist {
    fn from(d: DsArg) -> Self {
        match d {
            DsArg::Stack => Worklist::Stack,
            DsArg::Queue => Worklist::Queue,
            DsArg::Pqueue => Worklist::PriorityQueue,
        }
    }
}

/// Rewrites the report's single-dash long flags into their GNU forms, so that
/// `-ds pqueue`, `-nomedian` and `-all` work as the report writes them. A
/// token right after `-i`/`-o` is a file name and is left alone.
pub(super) fn legacy_args(args: impl IntoIterator<Item = std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    for arg in args {
        let after_path_flag = out
            .last()
            .and_then(|a| a.to_str())
            .is_some_and(|a| matches!(a, "-i" | "-o" | "--input" | "--output"));
        let rewritten = match arg.to_str() {
            _ if after_path_flag => None,
            Some("-ds") => Some("--ds".to_string()),
            Some(s) if s.starts_with("-ds=") => Some(format!("-{s}")),
            Some("-nomedian") => Some("--nomedian".to_string()),
            Some("-all") => Some("--all".to_string()),
            _ => None,
        };
        out.push(rewritten.map(Into::into).unwrap_or(arg));
    }
    out
}

/// `--max-added`: a number of added vertices, or a multiple of the input's
/// vertex count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum WorkLimit {
    /// This many added vertices, whatever the input.
    Vertices(usize),
    /// This many times the input's vertex count (`20x`).
    PerInputVertex(f64),
}

impl WorkLimit {
    /// The limit, in added vertices, for an input of `n` vertices (a
    /// multiple rounded down).
    pub(super) fn for_input(self, n: usize) -> usize {
        match self {
            WorkLimit::Vertices(limit) => limit,
            // (`as` saturates: a huge product is no limit.)
            WorkLimit::PerInputVertex(times) => (times * n as f64).floor() as usize,
        }
    }
}

/// A `--max-added` value: `N` (added vertices) or `Nx` (N, a finite
/// number from 0, times the input's vertex count).
pub(super) fn work_limit(s: &str) -> Result<WorkLimit, String> {
    let refused = || {
        format!("{s:?} is not a number of added vertices (such as 100000) or a multiple of the input's vertex count (such as 20x)")
    };
    match s.strip_suffix(['x', 'X']) {
        Some(times) => match times.parse::<f64>() {
            Ok(x) if x.is_finite() && x >= 0.0 => Ok(WorkLimit::PerInputVertex(x)),
            _ => Err(refused()),
        },
        None => s.parse::<usize>().map(WorkLimit::Vertices).map_err(|_| refused()),
    }
}

/// A weld tolerance: a finite distance, 0 or more (NaN and negatives would
/// weld nothing without a word, infinity everything).
pub(super) fn weld_distance(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if delmesh::repair::is_weld_distance(x) => Ok(x),
        _ => Err(format!(
            "{s:?} is not {}",
            delmesh::repair::RepairOptions::WELD_TOLERANCE_RANGE
        )),
    }
}

/// The tolerances of `--attribute-tolerance`: one relative tolerance (a
/// number from 0 to 1) for all attributes, or `KIND=REL` pairs separated by
/// commas (`texcoords`, `normals`, `colors` or `colours`, `properties`: a
/// PLY file's other vertex properties), the kinds not named keeping their
/// defaults.
pub(super) fn attribute_tolerances(s: &str) -> Result<Tolerances, String> {
    let relative = |text: &str| match text.trim().parse::<f64>() {
        Ok(x) if delmesh::attributes::is_relative_tolerance(x) => Ok(x),
        _ => Err(format!("{text:?} is not {}", Tolerances::RANGE)),
    };
    if !s.contains('=') {
        return relative(s).map(Tolerances::all);
    }
    let mut tolerances = Tolerances::default();
    for pair in s.split(',') {
        let (kind, value) = pair.split_once('=').unwrap_or((pair, ""));
        let slot = match kind.trim() {
            "texcoords" => &mut tolerances.texcoords,
            "normals" => &mut tolerances.normals,
            "colors" | "colours" => &mut tolerances.colors,
            "properties" => &mut tolerances.properties,
            other => {
                return Err(format!(
                    "{other:?} is not an attribute: give texcoords=REL, normals=REL, colors=REL or properties=REL (or \
                     one number for all)"
                ))
            }
        };
        *slot = relative(value)?;
    }
    Ok(tolerances)
}

/// An angle in degrees for `render`: any finite number (NaN or an
/// infinity would draw nothing).
pub(super) fn finite_degrees(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(format!("{s:?} is not a finite number of degrees")),
    }
}

/// An elevation in degrees for `render`: from -90 (from below) to 90
/// (from above).
pub(super) fn elevation_degrees(s: &str) -> Result<f64, String> {
    match finite_degrees(s)? {
        x if (-90.0..=90.0).contains(&x) => Ok(x),
        _ => Err(format!("{s:?} is not an elevation from -90 to 90 degrees")),
    }
}
