//! Writes the cone-like fan of the tests (`tests/common`, `cone_fan`) as an OBJ: one apex
//! vertex of valence N, the shape of CAD disks and cones, for timing `delmesh check` on it.
//!
//! ```sh
//! cargo run --release --example fan -- 20000 > fan.obj
//! ```

#[path = "../tests/common/mod.rs"]
mod common;

use std::io::Write;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(20_000, |n| n.parse().expect("a triangle count"));
    let (positions, triangles) = common::cone_fan(n);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for p in &positions {
        writeln!(out, "v {:?} {:?} {:?}", p[0], p[1], p[2]).expect("stdout");
    }
    for t in &triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).expect("stdout");
    }
}
