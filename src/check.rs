//! Placeholder with the verifier's API, until the real one lands.
#![allow(missing_docs)]
use std::path::Path;
pub const DELAUNAY_TOLERANCE: f64 = 1e-9;
#[derive(Debug, Default)]
pub struct CheckReport {
    pub input_vertices: usize,
    pub input_faces: usize,
    pub input_regions: usize,
    pub output_vertices: usize,
    pub output_faces: usize,
    pub added_vertices: usize,
    pub interior_edges: usize,
    pub non_delaunay_edges: usize,
    pub max_excess: f64,
    pub failures: Vec<String>,
}
impl CheckReport {
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    #[error("not implemented")]
    Todo,
}
pub fn check_files(_input: &Path, _output: &Path) -> Result<CheckReport, CheckError> {
    Err(CheckError::Todo)
}
