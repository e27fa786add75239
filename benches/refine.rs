//! `cargo bench`: the refine phase alone (Algorithm 2 on an already built
//! mesh), and the build phase, on the armadillo (52,000 faces) and the bunny.
//! The meshes are read once, outside the timed code. Needs `../shared/meshes`
//! beside the crate for the armadillo; the bunny ships in `data/`.

use std::path::{Path, PathBuf};

use delmesh::io;
use delmesh::mesh::Surface;
use delmesh::refine::{make_delaunay, Options};

fn main() {
    divan::main();
}

fn mesh_path(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../shared/meshes").join(name);
    if shared.exists() {
        shared
    } else {
        root.join("data").join(name)
    }
}

fn surface(name: &str) -> Surface {
    let path = mesh_path(name);
    let input = io::read_obj(&path).expect("readable mesh");
    io::build_surface(&input, &path).expect("valid mesh")
}

#[divan::bench(args = ["armadillo.obj", "bunny.obj"], sample_count = 20)]
fn refine(bencher: divan::Bencher, name: &str) {
    let base = surface(name);
    bencher.with_inputs(|| base.clone()).bench_local_values(|mut s| {
        make_delaunay(&mut s, &Options::default()).expect("refines");
        s
    });
}

#[divan::bench(args = ["armadillo.obj", "bunny.obj"], sample_count = 20)]
fn build(bencher: divan::Bencher, name: &str) {
    let path = mesh_path(name);
    let input = io::read_obj(&path).expect("readable mesh");
    bencher.bench_local(|| io::build_surface(&input, &path).expect("valid mesh"));
}
