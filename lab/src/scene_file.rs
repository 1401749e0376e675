//! Scene files: a mesh, a camera, an image size and uniform values, in TOML.
//!
//! ```toml
//! mesh = "sponza"              # or a path to .obj, .gltf, .glb, .ac or .acc, relative to this file
//! size = [960, 540]            # optional: the image size (`mrslc render --size` wins)
//! crease_angle = 45            # optional: degrees, for models without normals
//!
//! [camera]                     # optional: default Sponza's camera, or framing the mesh
//! eye = [-11.5, 2.2, -0.3]
//! target = [10.0, 4.5, 0.4]
//! up = [0, 1, 0]               # optional
//! fov = 60                     # optional: vertical field of view in degrees (default 50)
//!
//! # [[camera_path]]            # optional: keyframes of `mrslc render --frames`, at least two,
//! # eye = [-11.5, 2.2, -0.3]    # passed through in order by a Catmull-Rom spline (or
//! # target = [10.0, 4.5, 0.4]   # `camera_path = "walk"` before any table; Sponza's default)
//!
//! [uniforms]                   # optional: applied before any `mrslc render --set`
//! light_dir = [0.3, 0.9, 0.3]
//! shininess = 20
//! show_checker = true
//! albedo_map = "textures/albedo.png"                       # a texture2d: an sRGB colour image
//! roughness_map = { image = "textures/rough.png", srgb = false }   # data, read as stored
//! ```
//!
//! Uniforms are bound by name and type ([`crate::uniforms`]): numbers go to
//! a uniform with as many components, images to a `texture2d` (see
//! [`crate::image_texture`] for decoding, sRGB and mipmaps). A name the
//! program declares with another type is left at the program's default with
//! a warning ([`SceneBinding::applied`]), or is an error when the program
//! has no default for it; a name the program does not declare is an error.

use crate::camera::Camera;
use crate::camera_path::{CameraPath, Keyframe};
use crate::gbuffer::GBuffer;
use crate::gpu::Gpu;
use crate::image_texture::{ColorSpace, ImageError, ImageTexture};
use crate::mesh::{DEFAULT_CREASE_ANGLE, Mesh, MeshError};
use crate::mesh_scene::MeshScene;
use crate::raster::RasterError;
use crate::scene::Scene;
use crate::uniforms::{Applied, Ignored, Offered, UniformTypeError, Verdict};
use mrsl_runtime::Shader;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Default vertical field of view (degrees) of a scene file's camera: the demo scene's.
pub const DEFAULT_FOV: f32 = 50.0;

/// Why a scene file could not be used; names the file, and the key at fault.
#[derive(Debug, thiserror::Error)]
pub enum SceneFileError {
    #[error("cannot read scene file {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: invalid TOML: {message}", path.display())]
    Syntax { path: PathBuf, message: String },
    #[error("{}: `{key}`: {message}", path.display())]
    Key { path: PathBuf, key: String, message: String },
    #[error("{}: `mesh`: {source}", path.display())]
    Mesh {
        path: PathBuf,
        #[source]
        source: MeshError,
    },
    #[error("{}: {source}", path.display())]
    Raster {
        path: PathBuf,
        #[source]
        source: RasterError,
    },
    /// An image named under `[uniforms]` could not be loaded.
    #[error("{}: `{key}`: {source}", path.display())]
    Image {
        path: PathBuf,
        key: String,
        #[source]
        source: ImageError,
    },
    /// A uniform the program declares with another type and no default.
    #[error("{}: `{key}`: {source}", path.display())]
    UniformType {
        path: PathBuf,
        key: String,
        #[source]
        source: UniformTypeError,
    },
}

/// A value under `[uniforms]`.
#[derive(Debug, Clone, PartialEq)]
pub enum UniformValue {
    /// A number, a bool (0 or 1) or an array of them, flattened (matrices
    /// column by column): for a uniform with that many components.
    Numbers(Vec<f64>),
    /// An image file (resolved against the scene file's folder): for a
    /// `texture2d`.
    Image { path: PathBuf, color_space: ColorSpace },
}

impl UniformValue {
    /// What it offers a program ([`crate::uniforms`]).
    pub fn offered(&self) -> Offered {
        match self {
            UniformValue::Numbers(values) => Offered::Numbers(values.len()),
            UniformValue::Image { .. } => Offered::Texture,
        }
    }
}

/// What a scene file bound to a program ([`SceneFile::bind`]).
#[derive(Debug)]
pub struct SceneBinding {
    /// The uniforms set and the textures bound, by name; and the names the
    /// program declares with another type, left at its defaults.
    pub applied: Applied,
    /// The images, uploaded, for the program's `texture2d` uniforms of the same name.
    pub textures: Vec<(String, wgpu::Texture)>,
}

/// Which mesh a scene file names.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshSource {
    /// The built-in Dabrovic Sponza (`mesh = "sponza"`).
    Sponza,
    /// A model file, resolved against the scene file's folder.
    File(PathBuf),
}

/// A parsed scene file.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneFile {
    /// The file it was read from (for messages and relative paths).
    pub path: PathBuf,
    pub mesh: MeshSource,
    /// `None`: Sponza's default camera, or one framing the mesh.
    pub camera: Option<Camera>,
    pub size: Option<(u32, u32)>,
    pub crease_angle: Option<f32>,
    /// `camera_path`, if the file has one (see [`SceneFile::path`]).
    pub camera_path: Option<CameraPath>,
    /// Uniform values and images, in the order of the file.
    pub uniforms: Vec<(String, UniformValue)>,
}

impl SceneFile {
    pub fn load(path: impl AsRef<Path>) -> Result<SceneFile, SceneFileError> {
        let path = path.as_ref();
        let text =
            std::fs::read_to_string(path).map_err(|source| SceneFileError::Io { path: path.to_path_buf(), source })?;
        SceneFile::parse(&text, path)
    }

    /// Parses scene-file text; `path` resolves relative mesh paths and names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<SceneFile, SceneFileError> {
        let table: toml::Table = toml::from_str(text).map_err(|e| SceneFileError::Syntax {
            path: path.to_path_buf(),
            message: e.to_string().trim().to_string(),
        })?;
        let key_error =
            |key: &str, message: String| SceneFileError::Key { path: path.to_path_buf(), key: key.into(), message };
        for key in table.keys() {
            if !["mesh", "size", "crease_angle", "camera", "camera_path", "uniforms"].contains(&key.as_str()) {
                return Err(key_error(
                    key,
                    "unknown key (expected mesh, size, crease_angle, camera, camera_path or uniforms)".into(),
                ));
            }
        }
        let mesh = match table.get("mesh") {
            None => {
                return Err(key_error(
                    "mesh",
                    "missing: name a .obj, .gltf, .glb, .ac or .acc file, or \"sponza\"".into(),
                ));
            }
            Some(toml::Value::String(s)) if s == "sponza" => MeshSource::Sponza,
            Some(toml::Value::String(s)) => {
                let base = path.parent().unwrap_or(Path::new(""));
                MeshSource::File(base.join(s))
            }
            Some(other) => return Err(key_error("mesh", format!("expected a string, found {}", other.type_str()))),
        };
        let size = match table.get("size") {
            None => None,
            Some(v) => {
                let numbers = numbers(v).filter(|n| n.len() == 2).ok_or_else(|| {
                    key_error("size", format!("expected [width, height], found {}", describe_value(v)))
                })?;
                let side = |x: f64| (x.fract() == 0.0 && (1.0..=16384.0).contains(&x)).then_some(x as u32);
                match (side(numbers[0]), side(numbers[1])) {
                    (Some(w), Some(h)) => Some((w, h)),
                    _ => return Err(key_error("size", "each side must be a whole number from 1 to 16384".into())),
                }
            }
        };
        let crease_angle = match table.get("crease_angle") {
            None => None,
            Some(v) => match scalar(v) {
                Some(a) if (0.0..=180.0).contains(&a) => Some(a as f32),
                _ => return Err(key_error("crease_angle", "expected a number of degrees from 0 to 180".into())),
            },
        };
        let camera = match table.get("camera") {
            None => None,
            Some(v) => Some(camera(v).map_err(|(key, message)| key_error(&key, message))?),
        };
        let camera_path = match table.get("camera_path") {
            None => None,
            Some(v) => Some(camera_path(v).map_err(|(key, message)| key_error(&key, message))?),
        };
        let base = path.parent().unwrap_or(Path::new(""));
        let uniforms = match table.get("uniforms") {
            None => vec![],
            Some(v) => uniforms(v, base).map_err(|(key, message)| key_error(&key, message))?,
        };
        Ok(SceneFile { path: path.to_path_buf(), mesh, camera, size, crease_angle, camera_path, uniforms })
    }

    /// Sets the file's `[uniforms]` on `shader` and uploads its images, by
    /// name and type ([`crate::uniforms`]): a mismatch is a warning in the
    /// result when the program has a default, else
    /// [`SceneFileError::UniformType`]; a name the program does not declare
    /// is left out ([`Applied::ignored`]), and an image that cannot be loaded
    /// [`SceneFileError::Image`].
    pub fn bind(&self, gpu: &Gpu, shader: &mut Shader) -> Result<SceneBinding, SceneFileError> {
        let source = format!("scene file {}", self.path.display());
        let layout = shader.layout().clone();
        let mut applied = Applied::default();
        let mut textures = vec![];
        for (name, value) in &self.uniforms {
            let key = format!("uniforms.{name}");
            let verdict = crate::uniforms::check(&layout, &source, name, &value.offered())
                .map_err(|source| SceneFileError::UniformType { path: self.path.clone(), key: key.clone(), source })?;
            let key_error =
                |message: String| SceneFileError::Key { path: self.path.clone(), key: key.clone(), message };
            match verdict {
                Verdict::Absent => {
                    applied.ignored.push(Ignored { source: source.clone(), name: name.clone() });
                    continue;
                }
                Verdict::Skip(mismatch) => applied.warnings.push(mismatch),
                Verdict::Bind => {
                    match value {
                        UniformValue::Numbers(values) => {
                            shader.set_uniform(name, values).map_err(|e| key_error(e.to_string()))?
                        }
                        UniformValue::Image { path, color_space } => {
                            let image = ImageTexture::load(path, *color_space).map_err(|source| {
                                SceneFileError::Image { path: self.path.clone(), key: key.clone(), source }
                            })?;
                            textures.push((name.clone(), image.upload(gpu, name)));
                        }
                    }
                    applied.record(name);
                }
            }
        }
        Ok(SceneBinding { applied, textures })
    }

    /// Loads the mesh the file names (Sponza is shared between calls).
    pub fn load_mesh(&self) -> Result<Arc<Mesh>, SceneFileError> {
        let wrap = |source| SceneFileError::Mesh { path: self.path.clone(), source };
        match &self.mesh {
            MeshSource::Sponza => {
                if self.crease_angle.is_some_and(|a| a != DEFAULT_CREASE_ANGLE) {
                    let mut mesh = crate::fixtures::sponza().map_err(wrap)?;
                    mesh.compute_normals(self.crease_angle.unwrap_or(DEFAULT_CREASE_ANGLE));
                    Ok(Arc::new(mesh))
                } else {
                    crate::fixtures::sponza_shared().map_err(wrap)
                }
            }
            MeshSource::File(file) => {
                let mut mesh = Mesh::load(file).map_err(wrap)?;
                if let Some(angle) = self.crease_angle {
                    mesh.compute_normals(angle);
                }
                Ok(Arc::new(mesh))
            }
        }
    }

    /// The camera: the file's, else Sponza's default, else one that frames
    /// the mesh's bounds for the given aspect ratio.
    pub fn camera_for(&self, mesh: &Mesh, aspect: f32) -> Camera {
        match (&self.camera, &self.mesh) {
            (Some(c), _) => *c,
            (None, MeshSource::Sponza) => Scene::sponza_camera(),
            (None, MeshSource::File(_)) => match mesh.bounds() {
                Some(b) => Camera::frame(&b, DEFAULT_FOV, aspect),
                None => Camera::look_at([0.0, 0.0, 5.0], [0.0; 3], DEFAULT_FOV),
            },
        }
    }

    /// The camera path of `mrslc render --frames`: the file's
    /// `camera_path`, else Sponza's default walk for `mesh = "sponza"`;
    /// other meshes have none.
    pub fn path(&self) -> Option<CameraPath> {
        match (&self.camera_path, &self.mesh) {
            (Some(path), _) => Some(path.clone()),
            (None, MeshSource::Sponza) => Some(CameraPath::Walk),
            (None, MeshSource::File(_)) => None,
        }
    }

    /// Rasterises the scene: G-buffer textures (see [`crate::raster`]) and the camera used.
    pub fn textures_on(
        &self,
        gpu: &Gpu,
        size: (u32, u32),
    ) -> Result<(Vec<(String, wgpu::Texture)>, Camera), SceneFileError> {
        let scene = self.mesh_scene(gpu, size)?;
        let textures = scene
            .gbuffer(gpu, &scene.camera, size)
            .map_err(|source| SceneFileError::Raster { path: self.path.clone(), source })?;
        Ok((textures, scene.camera))
    }

    /// The mesh uploaded, with its camera for an image of `size` and its light rig.
    pub fn mesh_scene(&self, gpu: &Gpu, size: (u32, u32)) -> Result<MeshScene, SceneFileError> {
        let mesh = self.load_mesh()?;
        let camera = self.camera_for(&mesh, size.0 as f32 / size.1.max(1) as f32);
        MeshScene::new(gpu, &mesh, camera).map_err(|source| SceneFileError::Raster { path: self.path.clone(), source })
    }

    /// Rasterises the scene and reads the G-buffer back.
    pub fn render_on(&self, gpu: &Gpu, size: (u32, u32)) -> Result<GBuffer, SceneFileError> {
        let (textures, _) = self.textures_on(gpu, size)?;
        crate::raster::read_gbuffer(gpu, &textures)
            .map_err(|source| SceneFileError::Raster { path: self.path.clone(), source })
    }
}

/// `[camera]`: eye and target, optionally up and fov. Errors name the key at fault.
fn camera(v: &toml::Value) -> Result<Camera, (String, String)> {
    let toml::Value::Table(t) = v else {
        return Err(("camera".into(), format!("expected a table, found {}", v.type_str())));
    };
    for key in t.keys() {
        if !["eye", "target", "up", "fov"].contains(&key.as_str()) {
            return Err((format!("camera.{key}"), "unknown key (expected eye, target, up or fov)".into()));
        }
    }
    let vec3 = |key: &str, default: Option<[f32; 3]>| -> Result<[f32; 3], (String, String)> {
        match t.get(key) {
            None => default.ok_or_else(|| (format!("camera.{key}"), "missing: expected [x, y, z]".into())),
            Some(v) => numbers(v)
                .filter(|n| n.len() == 3)
                .map(|n| [n[0] as f32, n[1] as f32, n[2] as f32])
                .ok_or_else(|| (format!("camera.{key}"), format!("expected [x, y, z], found {}", describe_value(v)))),
        }
    };
    let fov = match t.get("fov") {
        None => DEFAULT_FOV,
        Some(v) => match scalar(v) {
            Some(a) if a > 0.0 && a < 180.0 => a as f32,
            _ => {
                return Err((
                    "camera.fov".into(),
                    format!("expected degrees between 0 and 180, found {}", describe_value(v)),
                ));
            }
        },
    };
    let camera = Camera {
        eye: vec3("eye", None)?,
        target: vec3("target", None)?,
        up: vec3("up", Some([0.0, 1.0, 0.0]))?,
        fov_y_degrees: fov,
    };
    camera.basis().map_err(|e| ("camera".to_string(), e.to_string()))?;
    Ok(camera)
}

/// `[uniforms]`: numbers, and images resolved against `base`, in the
/// order of the file. Errors name the key at fault.
fn uniforms(v: &toml::Value, base: &Path) -> Result<Vec<(String, UniformValue)>, (String, String)> {
    let toml::Value::Table(t) = v else {
        return Err(("uniforms".into(), format!("expected a table, found {}", v.type_str())));
    };
    let mut uniforms = vec![];
    for (name, v) in t {
        let key = format!("uniforms.{name}");
        let value = match v {
            toml::Value::String(file) => UniformValue::Image { path: base.join(file), color_space: ColorSpace::Srgb },
            toml::Value::Table(image) => image_value(image, base).map_err(|m| (key.clone(), m))?,
            _ => UniformValue::Numbers(numbers(v).filter(|n| !n.is_empty()).ok_or_else(|| {
                let expected = "expected a number, a bool, an array of them, or an image file";
                (key.clone(), format!("{expected}, found {}", describe_value(v)))
            })?),
        };
        uniforms.push((name.clone(), value));
    }
    Ok(uniforms)
}

/// `camera_path`: `"walk"`, or an array of at least two `{ eye, target }`
/// tables. Errors name the key at fault.
fn camera_path(v: &toml::Value) -> Result<CameraPath, (String, String)> {
    let expected = "expected \"walk\" or [[camera_path]] tables with eye and target";
    match v {
        toml::Value::String(s) if s == "walk" => Ok(CameraPath::Walk),
        toml::Value::Array(items) => {
            if items.len() < 2 {
                return Err((
                    "camera_path".into(),
                    format!("a path needs at least 2 keyframes, found {}", items.len()),
                ));
            }
            let mut keys = vec![];
            for (i, item) in items.iter().enumerate() {
                let here = format!("camera_path[{i}]");
                let toml::Value::Table(t) = item else {
                    return Err((here, format!("{expected}, found {}", describe_value(item))));
                };
                if let Some(key) = t.keys().find(|k| !["eye", "target"].contains(&k.as_str())) {
                    return Err((format!("{here}.{key}"), "unknown key (expected eye or target)".into()));
                }
                let vec3 = |key: &str| -> Result<[f32; 3], (String, String)> {
                    let at = format!("{here}.{key}");
                    let v = t.get(key).ok_or_else(|| (at.clone(), "missing: expected [x, y, z]".to_string()))?;
                    numbers(v)
                        .filter(|n| n.len() == 3 && n.iter().all(|x| x.is_finite()))
                        .map(|n| [n[0] as f32, n[1] as f32, n[2] as f32])
                        .ok_or_else(|| (at, format!("expected [x, y, z], found {}", describe_value(v))))
                };
                let (eye, target) = (vec3("eye")?, vec3("target")?);
                if eye == target {
                    return Err((here, "the eye and the target are the same point".into()));
                }
                keys.push(Keyframe { eye, target });
            }
            Ok(CameraPath::Keyframes(keys))
        }
        other => Err(("camera_path".into(), format!("{expected}, found {}", describe_value(other)))),
    }
}

/// `{ image = "FILE", srgb = BOOL }`: an image, sRGB unless `srgb = false`.
fn image_value(table: &toml::Table, base: &Path) -> Result<UniformValue, String> {
    for key in table.keys() {
        if !["image", "srgb"].contains(&key.as_str()) {
            return Err(format!("unknown key `{key}` (an image is {{ image = \"FILE\", srgb = true|false }})"));
        }
    }
    let file = match table.get("image") {
        Some(toml::Value::String(file)) => file,
        Some(other) => return Err(format!("`image`: expected a file name, found {}", describe_value(other))),
        None => return Err("missing `image = \"FILE\"`".into()),
    };
    let color_space = match table.get("srgb") {
        None | Some(toml::Value::Boolean(true)) => ColorSpace::Srgb,
        Some(toml::Value::Boolean(false)) => ColorSpace::Linear,
        Some(other) => return Err(format!("`srgb`: expected true or false, found {}", describe_value(other))),
    };
    Ok(UniformValue::Image { path: base.join(file), color_space })
}

/// A single number.
fn scalar(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// A number, a bool, or a (nested) array of them, flattened.
fn numbers(v: &toml::Value) -> Option<Vec<f64>> {
    match v {
        toml::Value::Integer(i) => Some(vec![*i as f64]),
        toml::Value::Float(f) => Some(vec![*f]),
        toml::Value::Boolean(b) => Some(vec![if *b { 1.0 } else { 0.0 }]),
        toml::Value::Array(items) => {
            let mut out = vec![];
            for item in items {
                out.extend(numbers(item)?);
            }
            Some(out)
        }
        _ => None,
    }
}

fn describe_value(v: &toml::Value) -> String {
    match v {
        toml::Value::Array(items) => format!("an array of {} item(s)", items.len()),
        toml::Value::String(s) => format!("string {s:?}"),
        toml::Value::Integer(i) => format!("integer {i}"),
        toml::Value::Float(f) => format!("float {f}"),
        toml::Value::Boolean(b) => format!("boolean {b}"),
        toml::Value::Datetime(d) => format!("datetime {d}"),
        toml::Value::Table(_) => "a table".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SceneFile, String> {
        SceneFile::parse(text, Path::new("hall.toml")).map_err(|e| e.to_string())
    }

    #[test]
    fn camera_paths_are_a_walk_or_keyframes_and_sponza_walks_by_default() {
        assert_eq!(parse("mesh = \"sponza\"").unwrap().path(), Some(CameraPath::Walk));
        assert_eq!(parse("mesh = \"hall.glb\"").unwrap().path(), None);
        assert_eq!(parse("mesh = \"hall.glb\"\ncamera_path = \"walk\"").unwrap().path(), Some(CameraPath::Walk));
        let keys = "mesh = \"sponza\"\n[[camera_path]]\neye = [0, 1, 2]\ntarget = [3, 4, 5]\n\
                    [[camera_path]]\neye = [1, 1, 2]\ntarget = [3, 4, 6]\n";
        let expected = CameraPath::Keyframes(vec![
            Keyframe { eye: [0.0, 1.0, 2.0], target: [3.0, 4.0, 5.0] },
            Keyframe { eye: [1.0, 1.0, 2.0], target: [3.0, 4.0, 6.0] },
        ]);
        assert_eq!(parse(keys).unwrap().path(), Some(expected), "a file's keyframes win over Sponza's walk");
    }

    #[test]
    fn camera_path_mistakes_name_their_key() {
        for (text, message) in [
            ("camera_path = \"run\"", "hall.toml: `camera_path`: expected \"walk\""),
            ("[[camera_path]]\neye = [0, 1, 2]\ntarget = [3, 4, 5]", "at least 2 keyframes, found 1"),
            (
                "[[camera_path]]\neye = [0, 1, 2]\ntarget = [3, 4, 5]\n[[camera_path]]\neye = [0, 1]",
                "`camera_path[1].eye`",
            ),
            (
                "[[camera_path]]\neye = [0, 1, 2]\ntarget = [3, 4, 5]\n[[camera_path]]\neye = [0, 1, 2]",
                "`camera_path[1].target`: missing",
            ),
            (
                "[[camera_path]]\neye = [0, 1, 2]\ntarget = [0, 1, 2]\n[[camera_path]]\neye = [0, 1, 2]\ntarget = [1, 1, 1]",
                "`camera_path[0]`: the eye and the target",
            ),
            (
                "[[camera_path]]\neye = [0, 1, 2]\ntarget = [3, 4, 5]\nfov = 3\n[[camera_path]]\neye = [0, 1, 2]\ntarget = [1, 1, 1]",
                "`camera_path[0].fov`: unknown key",
            ),
        ] {
            let e = parse(&format!("mesh = \"sponza\"\n{text}")).unwrap_err();
            assert!(e.contains(message), "{text}: {e}");
        }
    }
}
