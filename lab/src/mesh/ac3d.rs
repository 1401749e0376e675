//! AC3D text files (`.ac`), and the racing game TORCS's `.acc` dialect of
//! them (the `outdoor` scene's track, see docs/scenes.md).
//!
//! Hand-written: crates.io has no stand-alone AC3D reader (the format
//! appears only as one of many in large asset-interchange libraries, not
//! worth their dependencies for one line-oriented format), and TORCS's
//! dialect needs what plain AC3D lacks: triangle-strip surfaces (SURF type
//! 4), several `texture` lines per object (the first is the base colour),
//! several texture coordinates per `refs` line (the first set is used) and a
//! normal after each vertex (`x y z nx ny nz`).
//!
//! The file is a header line `AC3Db` (any `AC3D` version), `MATERIAL` lines
//! (or `MAT` ... `ENDMAT` blocks), then a hierarchy of `OBJECT`s, each with
//! optional `name`, `data`, `texture`, `texrep`, `texoff`, `rot`, `loc`,
//! `crease`, `url`, then `numvert` vertices, `numsurf` surfaces (`SURF
//! flags`, `mat index`, `refs n` and n lines `vertex u v`) and `kids n`
//! followed by its n children. A child's geometry is in its parent's frame:
//! world = parent(rot · v + loc).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{DEFAULT_CREASE_ANGLE, Mesh, MeshError, MeshWarning, drop_degenerate_triangles};
use crate::image_texture::TextureImage;
use crate::material::Material;
use crate::vector::normalize;
use glam::{Mat3, Vec3};

/// SURF flag: the surface is double-sided (TORCS draws it without culling).
pub const SURF_DOUBLE_SIDED: u32 = 0x20;
/// SURF flag: the surface is smooth-shaded (else flat).
pub const SURF_SHADED: u32 = 0x10;

/// TORCS's alpha-test rule: a base texture whose name contains one of these
/// is drawn with alpha testing at [`TORCS_ALPHA_CUTOFF`] (its trees, bushes
/// and fences); every other texture is opaque.
const TORCS_MASKED: [&str; 3] = ["tree", "trans-", "arbor"];
/// TORCS's alpha cut-off for its foliage: base textures whose names contain
/// `tree`, `trans-` or `arbor`.
pub const TORCS_ALPHA_CUTOFF: f32 = 0.65;

/// Deepest object hierarchy read (deeper is an error, not a stack overflow).
const MAX_DEPTH: usize = 256;

/// A parse error: the line (1-based) and what is wrong there.
type ParseError = (usize, String);

/// An object's vertices, and their normals where the file gives them.
type Vertices = (Vec<[f32; 3]>, Option<Vec<[f32; 3]>>);

/// An AC3D material (what the kit uses of it).
#[derive(Debug, Clone, PartialEq)]
struct AcMaterial {
    name: String,
    rgb: [f32; 3],
    shininess: f32,
    transparency: f32,
}

impl Default for AcMaterial {
    fn default() -> AcMaterial {
        AcMaterial { name: String::new(), rgb: [0.8, 0.8, 0.8], shininess: 0.0, transparency: 0.0 }
    }
}

/// A surface: its flags, material and corners (vertex index, first uv).
struct Surface {
    flags: u32,
    material: usize,
    refs: Vec<(usize, [f32; 2])>,
    line: usize,
}

/// An object with geometry, in world space.
struct Placed {
    name: String,
    texture: Option<String>,
    /// `texrep` and `texoff`: uv = uv_file · repeat + offset.
    repeat: [f32; 2],
    offset: [f32; 2],
    crease: Option<f32>,
    positions: Vec<[f32; 3]>,
    /// Per vertex, where the file gives normals (TORCS).
    normals: Option<Vec<[f32; 3]>>,
    surfaces: Vec<Surface>,
    /// Whether the object's world transform mirrors (turns the winding).
    mirrored: bool,
}

/// The non-empty lines of the file, with their numbers.
struct Lines<'a> {
    lines: Vec<(usize, &'a str)>,
    pos: usize,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str) -> Lines<'a> {
        let lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !l.is_empty()).collect();
        Lines { lines, pos: 0 }
    }
    fn next(&mut self) -> Option<(usize, &'a str)> {
        let line = self.lines.get(self.pos).copied();
        self.pos += usize::from(line.is_some());
        line
    }
    /// The next line, or an error saying what was expected there.
    fn expect(&mut self, what: &str) -> Result<(usize, &'a str), ParseError> {
        let last = self.lines.last().map_or(1, |(n, _)| *n);
        self.next().ok_or_else(|| (last, format!("the file ends where {what} was expected")))
    }
    /// How many lines are left (a bound for preallocating what a count announces).
    fn left(&self) -> usize {
        self.lines.len() - self.pos
    }
}

/// A line's first word and the rest.
fn split_key(line: &str) -> (&str, &str) {
    let line = line.trim();
    match line.find(char::is_whitespace) {
        Some(i) => (&line[..i], line[i..].trim_start()),
        None => (line, ""),
    }
}

/// `n` numbers at the start of `text`, finite; more may follow.
fn numbers<const N: usize>(text: &str, line: usize, what: &str) -> Result<[f32; N], ParseError> {
    let mut words = text.split_whitespace();
    let mut out = [0.0f32; N];
    for value in &mut out {
        let word = words.next().ok_or_else(|| (line, format!("{what}: expected {N} numbers")))?;
        *value = word
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| (line, format!("{what}: `{word}` is not a number")))?;
    }
    Ok(out)
}

/// A non-negative count (`numvert 12`).
fn count(text: &str, line: usize, what: &str) -> Result<usize, ParseError> {
    let word = text.split_whitespace().next().unwrap_or("");
    word.parse::<usize>().map_err(|_| (line, format!("{what}: `{word}` is not a count")))
}

/// A string in double quotes at the start of `text` (AC3D's names and file
/// names), and the rest; an unquoted word is taken as it is.
fn quoted(text: &str) -> (String, &str) {
    let text = text.trim_start();
    if let Some(rest) = text.strip_prefix('"') {
        match rest.find('"') {
            Some(end) => (rest[..end].to_string(), &rest[end + 1..]),
            None => (rest.to_string(), ""),
        }
    } else {
        let (word, rest) = split_key(text);
        (word.to_string(), rest)
    }
}

/// A `MATERIAL "name" rgb r g b amb ... shi s trans t` line (after the key),
/// or the lines of a `MAT` block joined.
fn parse_material(text: &str, line: usize) -> Result<AcMaterial, ParseError> {
    let (name, rest) = quoted(text);
    let mut material = AcMaterial { name, ..AcMaterial::default() };
    let mut words = rest.split_whitespace();
    while let Some(key) = words.next() {
        let take = match key {
            "rgb" | "amb" | "emis" | "spec" => 3,
            "shi" | "trans" => 1,
            other => return Err((line, format!("MATERIAL: unknown property `{other}`"))),
        };
        let mut values = [0.0f32; 3];
        for value in values.iter_mut().take(take) {
            let word = words.next().ok_or_else(|| (line, format!("MATERIAL: `{key}` lacks values")))?;
            *value = numbers::<1>(word, line, key)?[0];
        }
        match key {
            "rgb" => material.rgb = values,
            "shi" => material.shininess = values[0],
            "trans" => material.transparency = values[0].clamp(0.0, 1.0),
            _ => {}
        }
    }
    Ok(material)
}

/// A `MAT "name"` block up to `ENDMAT` (AC3D 6's form of a material).
fn parse_mat_block(lines: &mut Lines, first: &str, line: usize) -> Result<AcMaterial, ParseError> {
    let mut joined = first.to_string();
    loop {
        let (_, l) = lines.expect("ENDMAT")?;
        if l == "ENDMAT" {
            return parse_material(&joined, line);
        }
        joined.push(' ');
        joined.push_str(l);
    }
}

/// The object's own transform and what its header lines say.
struct Header {
    name: String,
    texture: Option<String>,
    repeat: [f32; 2],
    offset: [f32; 2],
    rot: Mat3,
    loc: Vec3,
    crease: Option<f32>,
}

/// The vertices (with normals, where each line has six numbers).
fn parse_vertices(lines: &mut Lines, n: usize) -> Result<Vertices, ParseError> {
    let mut positions = Vec::with_capacity(n.min(lines.left()));
    let mut normals: Option<Vec<[f32; 3]>> = None;
    for k in 0..n {
        let (line, text) = lines.expect("a vertex")?;
        let words = text.split_whitespace().count();
        positions.push(numbers::<3>(text, line, "vertex")?);
        if words >= 6 && (k == 0 || normals.is_some()) {
            let [_, _, _, nx, ny, nz] = numbers::<6>(text, line, "vertex normal")?;
            normals.get_or_insert_with(Vec::new).push([nx, ny, nz]);
        } else if normals.is_some() {
            return Err((line, "some vertices of the object have normals and this one has not".into()));
        }
    }
    Ok((positions, normals))
}

/// One surface: `SURF flags`, then `mat`, then `refs` and its corners.
fn parse_surface(lines: &mut Lines, vertices: usize) -> Result<Surface, ParseError> {
    let (line, text) = lines.expect("SURF")?;
    let (key, rest) = split_key(text);
    if key != "SURF" {
        return Err((line, format!("expected SURF, found `{key}`")));
    }
    let word = rest.split_whitespace().next().unwrap_or("");
    let flags = match word.strip_prefix("0x").or_else(|| word.strip_prefix("0X")) {
        Some(hex) => u32::from_str_radix(hex, 16),
        None => word.parse::<u32>(),
    }
    .map_err(|_| (line, format!("SURF: `{word}` is not a number")))?;
    let mut surface = Surface { flags, material: 0, refs: vec![], line };
    loop {
        let (line, text) = lines.expect("mat or refs")?;
        let (key, rest) = split_key(text);
        match key {
            "mat" => surface.material = count(rest, line, "mat")?,
            "refs" => {
                let n = count(rest, line, "refs")?;
                surface.refs.reserve(n.min(lines.left()));
                for _ in 0..n {
                    let (line, text) = lines.expect("a surface corner")?;
                    let (index, uv) = split_key(text);
                    let index = count(index, line, "corner")?;
                    if index >= vertices {
                        return Err((line, format!("corner refers to vertex {index}, the object has {vertices}")));
                    }
                    // Corners may lack texture coordinates (0, 0) or have
                    // several sets (TORCS); the first is used.
                    let uv = if uv.is_empty() { [0.0, 0.0] } else { numbers::<2>(uv, line, "corner")? };
                    surface.refs.push((index, uv));
                }
                return Ok(surface);
            }
            other => return Err((line, format!("expected mat or refs in a surface, found `{other}`"))),
        }
    }
}

/// Skips a `data n` block: n characters on the lines that follow.
fn skip_data(lines: &mut Lines, n: usize) -> Result<(), ParseError> {
    let mut read = 0usize;
    while read < n {
        let (_, text) = lines.expect("the object's data")?;
        read += text.len() + 1;
    }
    Ok(())
}

/// What one object reads: its geometry (world space) goes to `out`,
/// its children after it. Returns how many declared children the file
/// lacks (it ended first).
fn parse_object(
    lines: &mut Lines,
    parent: (Mat3, Vec3),
    depth: usize,
    out: &mut Vec<Placed>,
) -> Result<usize, ParseError> {
    let mut h = Header {
        name: String::new(),
        texture: None,
        repeat: [1.0, 1.0],
        offset: [0.0, 0.0],
        rot: Mat3::IDENTITY,
        loc: Vec3::ZERO,
        crease: None,
    };
    let mut geometry: Vertices = (vec![], None);
    let mut surfaces = vec![];
    let kids = loop {
        let (line, text) = lines.expect("kids")?;
        let (key, rest) = split_key(text);
        match key {
            "name" => h.name = quoted(rest).0,
            // TORCS: base, tiled, skids, shad; an unquoted word is "no texture".
            "texture" if h.texture.is_none() && rest.starts_with('"') => h.texture = Some(quoted(rest).0),
            "texture" | "url" | "subdiv" | "hidden" | "locked" | "folded" => {}
            "data" => skip_data(lines, count(rest, line, "data")?)?,
            "texrep" => h.repeat = numbers::<2>(rest, line, "texrep")?,
            "texoff" => h.offset = numbers::<2>(rest, line, "texoff")?,
            "crease" => h.crease = Some(numbers::<1>(rest, line, "crease")?[0]),
            "loc" => h.loc = Vec3::from(numbers::<3>(rest, line, "loc")?),
            // Row by row, each row the image of a basis vector (as plib and
            // OpenSceneGraph read it): the matrix's columns.
            "rot" => h.rot = Mat3::from_cols_array(&numbers::<9>(rest, line, "rot")?),
            "numvert" => geometry = parse_vertices(lines, count(rest, line, "numvert")?)?,
            "numsurf" => {
                let n = count(rest, line, "numsurf")?;
                surfaces.reserve(n.min(lines.left()));
                for _ in 0..n {
                    surfaces.push(parse_surface(lines, geometry.0.len())?);
                }
            }
            "kids" => break count(rest, line, "kids")?,
            other => return Err((line, format!("unknown object property `{other}`"))),
        }
    };
    let (rot, loc) = (parent.0 * h.rot, parent.0 * h.loc + parent.1);
    if !geometry.0.is_empty() && !surfaces.is_empty() {
        out.push(place(h, geometry, surfaces, (rot, loc)));
    }
    for k in 0..kids {
        let Some((line, text)) = lines.next() else { return Ok(kids - k) };
        if split_key(text).0 != "OBJECT" {
            return Err((line, format!("expected OBJECT (child {} of {kids}), found `{text}`", k + 1)));
        }
        if depth + 1 >= MAX_DEPTH {
            return Err((line, format!("objects nested more than {MAX_DEPTH} deep")));
        }
        let missing = parse_object(lines, (rot, loc), depth + 1, out)?;
        if missing > 0 {
            return Ok(missing + kids - k - 1);
        }
    }
    Ok(0)
}

/// An object's geometry in world space (normals by the inverse transpose).
fn place(h: Header, (positions, normals): Vertices, surfaces: Vec<Surface>, (rot, loc): (Mat3, Vec3)) -> Placed {
    let normal_matrix = rot.inverse().transpose();
    let positions = positions.iter().map(|&p| (rot * Vec3::from(p) + loc).to_array()).collect();
    let normals = normals.map(|ns| ns.iter().map(|&n| normalize(normal_matrix * Vec3::from(n)).to_array()).collect());
    Placed {
        name: h.name,
        texture: h.texture,
        repeat: h.repeat,
        offset: h.offset,
        crease: h.crease,
        positions,
        normals,
        surfaces,
        mirrored: rot.determinant() < 0.0,
    }
}

/// The whole file: its materials, its objects with geometry, and how many
/// declared child objects it lacks.
fn parse_document(text: &str) -> Result<(Vec<AcMaterial>, Vec<Placed>, usize), ParseError> {
    let mut lines = Lines::new(text);
    match lines.next() {
        Some((_, header)) if header.starts_with("AC3D") => {}
        Some((line, _)) => return Err((line, "the first line is not an AC3D header (`AC3Db`)".into())),
        None => return Err((1, "the file is empty".into())),
    }
    let (mut materials, mut objects, mut missing) = (vec![], vec![], 0);
    while let Some((line, text)) = lines.next() {
        let (key, rest) = split_key(text);
        match key {
            "MATERIAL" => materials.push(parse_material(rest, line)?),
            "MAT" => materials.push(parse_mat_block(&mut lines, rest, line)?),
            "OBJECT" => missing += parse_object(&mut lines, (Mat3::IDENTITY, Vec3::ZERO), 0, &mut objects)?,
            other => return Err((line, format!("expected MATERIAL or OBJECT, found `{other}`"))),
        }
    }
    Ok((materials, objects, missing))
}

impl Mesh {
    /// Loads an AC3D text file (`.ac`, or TORCS's `.acc`; see the module
    /// documentation). Each pair of (AC3D material, object texture) is one
    /// material id, in order of first use: named after the texture file (or
    /// the AC3D material's name, or `material<N>`). Polygons are
    /// triangulated by ear clipping, TORCS's triangle strips unrolled (their
    /// stitching triangles, which repeat a corner, dropped), lines skipped.
    /// Normals come from the file where its vertices have them (TORCS), else
    /// are computed per object: smooth surfaces (SURF flag 0x10) with the
    /// object's `crease` (default [`DEFAULT_CREASE_ANGLE`]), flat ones flat.
    /// Double-sided surfaces (flag 0x20) are read once: the rasteriser draws
    /// every triangle from both sides anyway.
    pub fn load_ac3d(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| MeshError::Io { path: path.to_path_buf(), source })?;
        // AC3D files are 8-bit text, Latin-1 by convention.
        let text: String = bytes.iter().map(|&b| b as char).collect();
        let (materials, objects, missing) = parse_document(&text).map_err(|(line, message)| MeshError::Ac3d {
            path: path.to_path_buf(),
            line,
            message,
        })?;
        let mut builder = Builder::new(path.parent().unwrap_or(Path::new(".")), materials);
        for object in &objects {
            builder.add(object).map_err(|(line, message)| MeshError::Ac3d {
                path: path.to_path_buf(),
                line,
                message,
            })?;
        }
        let mut mesh = builder.finish();
        if missing > 0 {
            mesh.warnings.push(MeshWarning::MissingObjects { count: missing });
        }
        if mesh.indices.is_empty() {
            return Err(MeshError::Empty { path: path.to_path_buf() });
        }
        Ok(mesh)
    }
}

/// Makes the mesh, object by object: material ids, textures (each file
/// decoded once), and what was skipped.
struct Builder {
    dir: PathBuf,
    materials: Vec<AcMaterial>,
    mesh: Mesh,
    ids: HashMap<(usize, Option<String>), u32>,
    textures: HashMap<PathBuf, Option<Arc<TextureImage>>>,
    degenerate: usize,
    lines: usize,
    unknown: usize,
}

impl Builder {
    fn new(dir: &Path, materials: Vec<AcMaterial>) -> Builder {
        Builder {
            dir: dir.to_path_buf(),
            materials,
            mesh: Mesh::default(),
            ids: HashMap::new(),
            textures: HashMap::new(),
            degenerate: 0,
            lines: 0,
            unknown: 0,
        }
    }

    /// Appends an object's surfaces: one piece for the smooth surfaces and
    /// one for the flat ones (each with its normals), vertices single-indexed
    /// by (vertex, uv, material).
    fn add(&mut self, object: &Placed) -> Result<(), ParseError> {
        // With the file's normals, one piece; else smooth and flat apart.
        let passes: &[Option<bool>] = if object.normals.is_some() { &[None] } else { &[Some(true), Some(false)] };
        for &smooth in passes {
            let mut piece = Mesh::default();
            let mut map: HashMap<(usize, [u32; 2], u32), u32> = HashMap::new();
            for surface in &object.surfaces {
                if smooth.is_some_and(|smooth| (surface.flags & SURF_SHADED != 0) != smooth) {
                    continue;
                }
                let material = self.material_id(surface, object)?;
                let corners: Vec<u32> = surface
                    .refs
                    .iter()
                    .map(|&(v, uv)| {
                        let uv =
                            [uv[0] * object.repeat[0] + object.offset[0], uv[1] * object.repeat[1] + object.offset[1]];
                        *map.entry((v, uv.map(f32::to_bits), material)).or_insert_with(|| {
                            piece.positions.push(object.positions[v]);
                            piece.normals.push(object.normals.as_ref().map_or([0.0; 3], |n| n[v]));
                            piece.uvs.push(uv);
                            piece.materials.push(material);
                            (piece.positions.len() - 1) as u32
                        })
                    })
                    .collect();
                self.triangles(surface, &corners, &mut piece);
            }
            if object.mirrored {
                piece.indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
            }
            self.degenerate += drop_degenerate_triangles(&piece.positions, &mut piece.indices);
            if piece.indices.is_empty() {
                continue;
            }
            let unit = |n: &[f32; 3]| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-3;
            if !piece.normals.iter().all(unit) {
                let crease = if smooth == Some(false) { 0.0 } else { object.crease.unwrap_or(DEFAULT_CREASE_ANGLE) };
                piece.compute_normals(crease);
            }
            self.mesh.append(&piece);
        }
        Ok(())
    }

    /// A surface's triangles, by its type: a polygon (0) ear-clipped, a
    /// TORCS triangle strip (4) unrolled with alternating winding; lines (1,
    /// 2) and unknown types are counted and skipped.
    fn triangles(&mut self, surface: &Surface, corners: &[u32], piece: &mut Mesh) {
        match surface.flags & 0xF {
            0 if corners.len() >= 3 => super::obj::triangulate(&piece.positions, corners, &mut piece.indices),
            4 if corners.len() >= 3 => {
                for k in 2..corners.len() {
                    let t = if k % 2 == 0 {
                        [corners[k - 2], corners[k - 1], corners[k]]
                    } else {
                        [corners[k - 1], corners[k - 2], corners[k]]
                    };
                    // Strips are stitched by triangles that repeat a corner.
                    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                        piece.indices.extend(t);
                    }
                }
            }
            0 | 4 => self.degenerate += 1,
            1 | 2 => self.lines += 1,
            _ => self.unknown += 1,
        }
    }

    /// The id of the surface's (material, texture) pair, made on first use.
    fn material_id(&mut self, surface: &Surface, object: &Placed) -> Result<u32, ParseError> {
        let count = self.materials.len().max(1);
        if surface.material >= count {
            return Err((
                surface.line,
                format!("surface of `{}` uses material {}, the file has {count}", object.name, surface.material),
            ));
        }
        let key = (surface.material, object.texture.clone());
        if let Some(&id) = self.ids.get(&key) {
            return Ok(id);
        }
        let ac = self.materials.get(surface.material).cloned().unwrap_or_default();
        let mut name = match &object.texture {
            Some(texture) => texture.clone(),
            None if !ac.name.is_empty() => ac.name.clone(),
            None => format!("material{}", surface.material),
        };
        if self.mesh.material_names.contains(&name) {
            name = format!("{name} (material {})", surface.material);
        }
        let params = self.material(&ac, object.texture.as_deref(), &name);
        let id = self.mesh.material_names.len() as u32;
        self.mesh.material_names.push(name);
        self.mesh.material_params.push(params);
        self.ids.insert(key, id);
        Ok(id)
    }

    /// The kit's material for an AC3D material and an object's texture.
    ///
    /// A textured surface's base colour is its texture alone (AC3D's colour
    /// modulates it in TORCS, which adds it back as emission; here it would
    /// only darken), an untextured one's the material's `rgb`; alpha is 1 −
    /// `trans` (drawn opaque). Roughness comes from the shininess exponent
    /// `shi` as from MTL's `Ns`: α = √(2 / (shi + 2)), roughness = √α.
    fn material(&mut self, ac: &AcMaterial, texture: Option<&str>, name: &str) -> Material {
        let alpha = 1.0 - ac.transparency;
        let mut out = Material {
            base_color: if texture.is_some() {
                [1.0, 1.0, 1.0, alpha]
            } else {
                [ac.rgb[0], ac.rgb[1], ac.rgb[2], alpha]
            },
            roughness: (2.0 / (ac.shininess.max(0.0) + 2.0)).sqrt().sqrt(),
            flip_v: true,
            ..Material::default()
        };
        if ac.transparency > 0.0 {
            self.mesh.warnings.push(MeshWarning::Unsupported {
                material: name.to_string(),
                feature: "transparency (drawn opaque; alpha is in the albedo channel)".into(),
            });
        }
        if let Some(file) = texture {
            out.base_color_texture = self.texture(file, name);
            if TORCS_MASKED.iter().any(|m| file.contains(m)) {
                out.alpha_cutoff = Some(TORCS_ALPHA_CUTOFF);
            }
        }
        out
    }

    /// A texture next to the model, decoded once. TORCS names some SGI
    /// images (`.rgb`) that Debian's package ships as PNG: where the named
    /// file is missing, the PNG of the same name is read.
    fn texture(&mut self, file: &str, material: &str) -> Option<Arc<TextureImage>> {
        let mut path = self.dir.join(file);
        let sgi = path.extension().and_then(|e| e.to_str()).is_some_and(|e| ["rgb", "rgba", "sgi", "bw"].contains(&e));
        if sgi && !path.is_file() {
            path.set_extension("png");
        }
        let warnings = &mut self.mesh.warnings;
        self.textures
            .entry(path.clone())
            .or_insert_with(|| match TextureImage::load(&path) {
                Ok(image) => Some(Arc::new(image)),
                Err(message) => {
                    warnings.push(MeshWarning::Texture {
                        material: material.to_string(),
                        texture: format!("`texture \"{file}\"`"),
                        message,
                    });
                    None
                }
            })
            .clone()
    }

    /// The mesh, with the warnings for what was skipped.
    fn finish(mut self) -> Mesh {
        if self.degenerate > 0 {
            self.mesh.warnings.push(MeshWarning::DegenerateFaces { count: self.degenerate });
        }
        for (count, what) in
            [(self.lines, "line surfaces (SURF types 1 and 2)"), (self.unknown, "surfaces of unknown SURF types")]
        {
            if count > 0 {
                self.mesh.warnings.push(MeshWarning::Skipped { count, what: what.into() });
            }
        }
        self.mesh.ensure_tangents();
        self.mesh
    }
}
