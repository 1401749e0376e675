//! bevy_mrsl: mrsl programs in Bevy 0.19, over the G-buffer Bevy's prepass
//! writes.
//!
//! Add [`MrslPlugin`] to the app and an [`MrslCamera`] to a 3D camera. After
//! Bevy's prepass, the plugin runs the program's passes in the camera's mode
//! (mrsl-runtime interprets the mode's plan; nothing here dispatches on its
//! own), reading the prepass textures (`ViewPrepassTextures`: depth,
//! normals, motion vectors, the deferred G-buffer and its lighting-pass id)
//! as the program's channels. Its outputs are [`Image`] assets
//! ([`MrslOutputs`]) sized to the camera's viewport; the first one is drawn
//! over the camera's image after Bevy's main pass (premultiplied alpha: a
//! program writes alpha 0 where Bevy's own lighting should show), unless
//! [`MrslCamera::composite`] is off. Uniforms come from [`MrslUniforms`]; the
//! `@depth` channels' inverse view-projection is set from the camera. After
//! each frame [`MrslReport`] holds the statistics of the frame before, or
//! what went wrong.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_mrsl::{MrslCamera, MrslPlugin, MrslProgram, Mode};
//!
//! fn setup(mut commands: Commands) {
//!     let program = MrslProgram::compile(include_str!("../examples/lighting.mrsl"), "lighting.mrsl").unwrap();
//!     commands.spawn((Camera3d::default(), MrslCamera::new(program, Mode::Coarse4x4)));
//! }
//! # fn main() { App::new().add_plugins(MrslPlugin).add_systems(Startup, setup); }
//! ```

mod bindings;
mod composite;
mod extract;
mod outputs;
mod pass;
mod report;

use bevy::app::{App, Plugin, PostUpdate, Update};
use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::ecs::prelude::*;
use bevy::render::{ExtractSchedule, RenderApp};
use std::collections::HashMap;
use std::sync::Arc;

pub use bindings::PrepassTexture;
pub use mrsl_runtime::{CompiledProgram, Error, Mode, Stats};
pub use mrsl_runtime_wgpu29 as mrsl_runtime;
pub use outputs::MrslOutputs;
pub use report::MrslReport;

/// Runs the programs of every camera with an [`MrslCamera`].
pub struct MrslPlugin;

impl Plugin for MrslPlugin {
    fn build(&self, app: &mut App) {
        let shared = report::Shared::default();
        app.insert_resource(shared.clone())
            .add_systems(Update, bindings::require_prepasses)
            .add_systems(PostUpdate, (outputs::fit_outputs, report::publish));
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        render_app
            .insert_resource(shared)
            .init_resource::<pass::Shaders>()
            .init_resource::<composite::Pipelines>()
            .add_systems(ExtractSchedule, (extract::extract_cameras, pass::drop_unused))
            .add_systems(Core3d, pass::run.after(Core3dSystems::Prepass).before(Core3dSystems::MainPass))
            .add_systems(Core3d, composite::run.after(Core3dSystems::MainPass).before(Core3dSystems::EarlyPostProcess));
    }
}

/// A compiled mrsl program, shared by the cameras that run it (cloning is
/// cheap). A camera's kernels are rebuilt when its program is replaced by
/// another one.
#[derive(Clone, Debug)]
pub struct MrslProgram(Arc<CompiledProgram>);

impl MrslProgram {
    /// Compiles mrsl source for every mode; the error is the rendered
    /// diagnostics (`file_name` names the source in them).
    #[cfg(feature = "compile")]
    pub fn compile(source: &str, file_name: &str) -> Result<MrslProgram, Error> {
        mrsl_runtime::compile(source, file_name).map(MrslProgram::from)
    }

    /// Reads the kernels and layout `mrslc compile -o DIR` wrote.
    pub fn read_dir(dir: &std::path::Path) -> Result<MrslProgram, mrsl_runtime::ReadError> {
        CompiledProgram::read_dir(dir, None).map(MrslProgram::from)
    }

    /// The compiled kernels and layout.
    pub fn compiled(&self) -> &CompiledProgram {
        &self.0
    }

    fn same(&self, other: &MrslProgram) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl From<CompiledProgram> for MrslProgram {
    fn from(program: CompiledProgram) -> MrslProgram {
        MrslProgram(Arc::new(program))
    }
}

/// Runs an mrsl program for this camera. Every field may change from frame
/// to frame: the mode, forced refinement and statistics switch at once, a
/// new program rebuilds the camera's kernels.
#[derive(Component, Clone, Debug)]
pub struct MrslCamera {
    pub program: MrslProgram,
    pub mode: Mode,
    /// Every refine predicate true: the image then equals the reference's.
    pub force_refine: bool,
    /// Count re-evaluations and write the refine mask ([`MrslReport`]); off,
    /// the frame costs what it costs displayed.
    pub statistics: bool,
    /// The hierarchical mode's similarity threshold.
    pub similarity: f32,
    /// Draw the first output over the camera's image after Bevy's main pass.
    pub composite: bool,
    /// Which prepass texture each channel reads, where the program's layout
    /// does not say it ([`PrepassTexture::for_channel`]).
    pub bindings: HashMap<String, PrepassTexture>,
}

impl MrslCamera {
    /// `program` in `mode`, statistics on, composited.
    pub fn new(program: MrslProgram, mode: Mode) -> MrslCamera {
        MrslCamera {
            program,
            mode,
            force_refine: false,
            statistics: true,
            similarity: mrsl_runtime::DispatchOptions::DEFAULT_SIMILARITY,
            composite: true,
            bindings: HashMap::new(),
        }
    }

    /// Binds channel `name` to a prepass texture (over the default).
    pub fn bind(mut self, name: &str, texture: PrepassTexture) -> MrslCamera {
        self.bindings.insert(name.to_string(), texture);
        self
    }
}

/// The program's uniforms for this camera, by name, in the order the
/// layout lists a value's components (matrices column by column); checked
/// by the runtime each frame (an error lands in [`MrslReport`]).
#[derive(Component, Clone, Debug, Default)]
pub struct MrslUniforms(pub HashMap<String, Vec<f64>>);

impl MrslUniforms {
    pub fn set(&mut self, name: &str, values: impl IntoIterator<Item = f64>) -> &mut MrslUniforms {
        self.0.insert(name.to_string(), values.into_iter().collect());
        self
    }
}
