//! The test models the kit renders, and where they are: the Dabrovic
//! Sponza (a test fixture of the crates.io package `obj-rs` 0.7.4, which
//! cargo unpacks in its registry), the Castle Game Engine's dungeon
//! (fetched by `scripts/fetch-dungeon.sh`, or Debian's package), TORCS's
//! "forza" track (the `outdoor` scene, `scripts/fetch-outdoor.sh`) and a
//! link of the Franka Panda robot arm (the `small` scene,
//! `scripts/fetch-small.sh`). The library does not search the disk by
//! itself: the application says where Sponza is ([`set_sponza_path`], or
//! [`locate_sponza`] for cargo's registry) or the environment does
//! (`MRSL_SPONZA`, `MRSL_DUNGEON`, `MRSL_OUTDOOR`, `MRSL_SMALL`); the
//! fetched models are also looked for where their scripts put them. Each
//! model is loaded once per process and shared.
//!
//! The chosen paths and the loaded models live in process-wide mutexes: the
//! tools and the test harness set a path once at start-up and every scene
//! built afterwards reads it, wherever it is built.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::mesh::{Mesh, MeshError};

/// Where the Dabrovic Sponza lies inside the `obj-rs` 0.7.4 package.
const SPONZA_IN_PACKAGE: &str = "tests/fixtures/sponza.obj";
const SPONZA_PACKAGE: &str = "obj-rs";
const SPONZA_VERSION: &str = "0.7.4";

/// The Sponza path the application chose ([`set_sponza_path`]).
static SPONZA_PATH: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Tells [`sponza_path`] where the Dabrovic Sponza OBJ file is. The library
/// does not go looking for it: the command-line tool and the tests find it
/// in cargo's registry ([`find_sponza_in_cargo_home`]) and say so here.
pub fn set_sponza_path(path: PathBuf) {
    *SPONZA_PATH.lock().unwrap_or_else(|e| e.into_inner()) = Some(path);
}

/// The path of the Dabrovic Sponza OBJ file: the one given to
/// [`set_sponza_path`], else `$MRSL_SPONZA`.
pub fn sponza_path() -> Result<PathBuf, MeshError> {
    let mut searched = vec![];
    let chosen = SPONZA_PATH.lock().unwrap_or_else(|e| e.into_inner()).clone();
    for candidate in chosen.into_iter().chain(std::env::var_os("MRSL_SPONZA").map(PathBuf::from)) {
        if candidate.is_file() {
            return Ok(candidate);
        }
        searched.push(candidate);
    }
    Err(MeshError::SponzaNotFound { searched })
}

/// Where cargo unpacked `obj-rs` 0.7.4's Sponza under `cargo_home`
/// (`$CARGO_HOME`, by default `~/.cargo`): `registry/src/*/obj-rs-0.7.4/tests/fixtures/sponza.obj`.
/// Building this crate makes cargo download and unpack that package.
pub fn find_sponza_in_cargo_home(cargo_home: &Path) -> Option<PathBuf> {
    let mut registries: Vec<PathBuf> = std::fs::read_dir(cargo_home.join("registry").join("src"))
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    registries.sort();
    registries
        .into_iter()
        .map(|r| r.join(format!("{SPONZA_PACKAGE}-{SPONZA_VERSION}")).join(SPONZA_IN_PACKAGE))
        .find(|p| p.is_file())
}

/// Tells [`sponza_path`] where cargo unpacked the Dabrovic Sponza (the
/// `obj-rs` 0.7.4 package in `$CARGO_HOME`, by default `~/.cargo`), unless
/// `$MRSL_SPONZA` names the file: what the command-line tool and the render
/// tests do at start-up.
pub fn locate_sponza() {
    if std::env::var_os("MRSL_SPONZA").is_some() {
        return;
    }
    let cargo_home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".cargo")));
    if let Some(path) = cargo_home.and_then(|home| find_sponza_in_cargo_home(&home)) {
        set_sponza_path(path);
    }
}

/// The Dabrovic Sponza, with computed normals (crease angle
/// [`crate::mesh::DEFAULT_CREASE_ANGLE`]) and its 35 materials numbered 0..34
/// in the order the file first uses them.
pub fn sponza() -> Result<Mesh, MeshError> {
    Mesh::load_obj(sponza_path()?)
}

/// The Sponza mesh, loaded once per process and shared.
pub fn sponza_shared() -> Result<Arc<Mesh>, MeshError> {
    static CACHE: Mutex<Option<Arc<Mesh>>> = Mutex::new(None);
    shared(&CACHE, sponza)
}

/// The dungeon path the application chose ([`set_dungeon_path`]).
static DUNGEON_PATH: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Where the dungeon level lies in Debian's `castle-game-engine-doc` package.
const DUNGEON_IN_PACKAGE: &str =
    "/usr/share/doc/castle-game-engine-doc/examples/third_person_navigation/data/level/level-dungeon.gltf";

/// Tells [`dungeon_path`] where the dungeon's `level-dungeon.gltf` is.
pub fn set_dungeon_path(path: PathBuf) {
    *DUNGEON_PATH.lock().unwrap_or_else(|e| e.into_inner()) = Some(path);
}

/// The places [`dungeon_path`] looks, in order: the path given to
/// [`set_dungeon_path`], `$MRSL_DUNGEON`, where `scripts/fetch-dungeon.sh`
/// puts it (`$XDG_DATA_HOME/mrsl/castle-dungeon/level-dungeon.gltf`,
/// `XDG_DATA_HOME` defaulting to `~/.local/share`), and where Debian's
/// package installs it.
pub fn dungeon_candidates() -> Vec<PathBuf> {
    let chosen = DUNGEON_PATH.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let mut candidates = fetched_candidates(chosen, "MRSL_DUNGEON", "castle-dungeon/level-dungeon.gltf");
    candidates.push(PathBuf::from(DUNGEON_IN_PACKAGE));
    candidates
}

/// `$XDG_DATA_HOME` (absolute), else `~/.local/share`: where the fetch
/// scripts put the models, under `mrsl/`.
fn data_home() -> Option<PathBuf> {
    std::env::var_os("XDG_DATA_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/share")))
}

/// The places a fetched model is looked for: the path the application
/// chose, the environment variable `variable`, and `$XDG_DATA_HOME/mrsl/`
/// followed by `fetched` (where its fetch script puts it).
fn fetched_candidates(chosen: Option<PathBuf>, variable: &str, fetched: &str) -> Vec<PathBuf> {
    chosen
        .into_iter()
        .chain(std::env::var_os(variable).map(PathBuf::from))
        .chain(data_home().map(|d| d.join("mrsl").join(fetched)))
        .collect()
}

/// The path of the dungeon level: the first of [`dungeon_candidates`] that exists.
pub fn dungeon_path() -> Result<PathBuf, MeshError> {
    let searched = dungeon_candidates();
    searched.iter().find(|p| p.is_file()).cloned().ok_or(MeshError::DungeonNotFound { searched })
}

/// The dungeon mesh with its materials and textures, loaded once per process and shared.
pub fn dungeon_shared() -> Result<Arc<Mesh>, MeshError> {
    static CACHE: Mutex<Option<Arc<Mesh>>> = Mutex::new(None);
    shared(&CACHE, || Mesh::load_gltf(dungeon_path()?))
}

/// The outdoor scene's path the application chose ([`set_outdoor_path`]).
static OUTDOOR_PATH: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Tells [`outdoor_path`] where TORCS's `forza.acc` is.
pub fn set_outdoor_path(path: PathBuf) {
    *OUTDOOR_PATH.lock().unwrap_or_else(|e| e.into_inner()) = Some(path);
}

/// The places [`outdoor_path`] looks, in order: the path given to
/// [`set_outdoor_path`], `$MRSL_OUTDOOR`, and where
/// `scripts/fetch-outdoor.sh` puts it
/// (`$XDG_DATA_HOME/mrsl/torcs-forza/forza.acc`).
pub fn outdoor_candidates() -> Vec<PathBuf> {
    let chosen = OUTDOOR_PATH.lock().unwrap_or_else(|e| e.into_inner()).clone();
    fetched_candidates(chosen, "MRSL_OUTDOOR", "torcs-forza/forza.acc")
}

/// The path of the outdoor scene's track: the first of [`outdoor_candidates`] that exists.
pub fn outdoor_path() -> Result<PathBuf, MeshError> {
    let searched = outdoor_candidates();
    searched.iter().find(|p| p.is_file()).cloned().ok_or(MeshError::OutdoorNotFound { searched })
}

/// TORCS's forza track with its textures, loaded once per process and shared.
pub fn outdoor_shared() -> Result<Arc<Mesh>, MeshError> {
    static CACHE: Mutex<Option<Arc<Mesh>>> = Mutex::new(None);
    shared(&CACHE, || Mesh::load_ac3d(outdoor_path()?))
}

/// The small scene's path the application chose ([`set_small_path`]).
static SMALL_PATH: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Tells [`small_path`] where the Franka Panda's `link6.obj` is.
pub fn set_small_path(path: PathBuf) {
    *SMALL_PATH.lock().unwrap_or_else(|e| e.into_inner()) = Some(path);
}

/// The places [`small_path`] looks, in order: the path given to
/// [`set_small_path`], `$MRSL_SMALL`, and where `scripts/fetch-small.sh`
/// puts it (`$XDG_DATA_HOME/mrsl/franka-panda/link6.obj`).
pub fn small_candidates() -> Vec<PathBuf> {
    let chosen = SMALL_PATH.lock().unwrap_or_else(|e| e.into_inner()).clone();
    fetched_candidates(chosen, "MRSL_SMALL", "franka-panda/link6.obj")
}

/// The path of the small scene's model: the first of [`small_candidates`] that exists.
pub fn small_path() -> Result<PathBuf, MeshError> {
    let searched = small_candidates();
    searched.iter().find(|p| p.is_file()).cloned().ok_or(MeshError::SmallNotFound { searched })
}

/// The Franka Panda's link 6 with its materials, loaded once per process and shared.
pub fn small_shared() -> Result<Arc<Mesh>, MeshError> {
    static CACHE: Mutex<Option<Arc<Mesh>>> = Mutex::new(None);
    shared(&CACHE, || Mesh::load_obj(small_path()?))
}

/// The generated scene's mesh ([`crate::procedural::city`]), made once per process and shared.
pub fn generated_shared() -> Result<Arc<Mesh>, MeshError> {
    static CACHE: Mutex<Option<Arc<Mesh>>> = Mutex::new(None);
    shared(&CACHE, || Ok(crate::procedural::city()))
}

/// The mesh in `cache`, else `load`ed into it (a failure is not kept: the
/// next call tries again). The lock is held while loading, so that threads
/// asking at once load the model once.
fn shared(
    cache: &Mutex<Option<Arc<Mesh>>>,
    load: impl FnOnce() -> Result<Mesh, MeshError>,
) -> Result<Arc<Mesh>, MeshError> {
    let mut guard = cache.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(mesh) = guard.as_ref() {
        return Ok(mesh.clone());
    }
    let mesh = Arc::new(load()?);
    *guard = Some(mesh.clone());
    Ok(mesh)
}
