//! IGES 5.3 lossless reader/writer with NURBS views of every surface.

pub mod convert;
mod document;
mod edit;
pub mod entity;
mod error;
mod global;
mod read;
pub mod write;

pub use convert::{FaceRef, NurbsInfo, SurfaceInfo};
pub use document::{Directory, Document, Entity, EntityId, Param, Status, Value};
pub use entity::View;
pub use error::{Error, Position, Result};
pub use global::{Global, Units};
