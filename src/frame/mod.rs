//! Framing, shared by the CPU stages and their GPU twins: what every view
//! derives from its inputs before a method runs.
//!
//! * `light_view.rs`: meshes checked and moved to the light's space in the
//!   kernels' depth unit, the map grids fitted (`frame_scene`); the mesh
//!   pipeline's settings and result.
//! * `depth.rs`: the user's depth maps checked and brought to the kernels'
//!   unit; orthographic (sun) maps as the kernels read them.
//!
//! The eye view's framing (the visible points' light space, the focused
//! grid, the casters) is an eye-view stage: `crate::eye::framing`.

pub mod depth;
pub mod light_view;

pub(crate) use depth::check_depth_inputs;
pub use depth::DepthInUnit;
pub use depth::{check_depth, orthographic_maps};
pub(crate) use light_view::frame_scene;
pub use light_view::FramedScene;
pub use light_view::{light_space_triangles, MapSettings, ShadowResult};
