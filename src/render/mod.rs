//! Renderers: simulation state in, `tiny_skia::Pixmap` out. Nothing here does I/O except
//! decoding image files the user names.
//!
//! The mesh renderer ([`mesh`]) is shared by the ocean and the lake: see its module docs for
//! the API ("one renderer, two height sources": a [`crate::sim::surface::Surface`], a
//! [`camera::Camera`], an [`sky::Environment`] and a [`shade::WaterLook`]).

pub mod background;
pub mod camera;
pub mod caustics;
pub mod clouds;
pub mod foam_texture;
pub mod lake;
pub mod light;
pub mod mesh;
pub mod mirror;
pub mod ocean;
pub mod plot;
pub mod pool;
pub mod raster;
pub mod shade;
pub mod shore;
pub mod sky;
pub mod supersample;
pub mod texture;
pub mod vec3;
