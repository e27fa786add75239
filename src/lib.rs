//! delmesh turns a triangle mesh into a *Delaunay mesh* — one whose every
//! interior edge has opposite angles summing to at most π — with exactly the
//! same geometry: it only adds vertices on existing edges and only flips edges
//! inside flat regions. It implements Algorithm 2 of Liu, Xu, Fan and He,
//! *Efficient Construction and Simplification of Delaunay Meshes* (ACM TOG
//! 2015), with the sample-choice heuristics of the DelMesh tool.
//!
//! ```
//! use delmesh::{io::InputMesh, refine::Options, mesh::Surface};
//! use glam::DVec3;
//!
//! // A thin rhombus folded along its long diagonal: that diagonal is not
//! // Delaunay and, the two faces not being coplanar, must be split.
//! let input = InputMesh {
//!     positions: vec![
//!         DVec3::new(-2.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0),
//!         DVec3::new(0.0, 0.5, 0.0), DVec3::new(0.0, -0.4, 0.3),
//!     ],
//!     triangles: vec![[0, 1, 2], [1, 0, 3]],
//!     ..Default::default()
//! };
//! let mut surface = Surface::new(input.positions.clone(), &input.triangles).unwrap();
//! let stats = delmesh::refine::make_delaunay(&mut surface, &Options::default()).unwrap();
//! assert_eq!(stats.non_delaunay_after, 0);
//! assert!(stats.splits >= 1);
//! // Input vertices first and untouched; added ones lie on input edges.
//! assert_eq!(&surface.positions[..4], &input.positions[..]);
//! ```

pub mod check;
pub mod error;
pub mod geometry;
pub mod hash;
pub mod io;
pub mod mesh;
pub mod refine;
pub mod repair;
pub mod samples;

pub use error::{Error, Result};
