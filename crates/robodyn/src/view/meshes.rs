//! The `<visual>`s of a URDF's links (STL meshes, boxes, cylinders, spheres), placed in the
//! Khalil–Kleinfinger frames robodyn made from the same file.
//!
//! The URDF importer puts frame R_j at the joint with z_j along its axis and keeps link j's name
//! (`io::urdf`); the URDF link frame is R_j C_j with a constant C_j. C_j is found here without
//! the importer's internals: at q = 0 the URDF link frame is the product of the joint origins
//! from the root, and R_j is 0T_j(0) ([`frame_transforms_per_frame`]), so C_j = 0T_j(0)^-1 (URDF link
//! pose at 0). A visual at `<origin>` O_v of the link is drawn at R_j C_j O_v.

use crate::error::{Error, Result};
use crate::geometry::{frame_transforms_per_frame, Transform};
use crate::Robot;
use base64::Engine as _;
use nalgebra::{Matrix3, Translation3, UnitQuaternion, Vector3};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Default cap on the bytes of mesh files embedded in one page (32 MiB; base64 adds a third).
pub const DEFAULT_MESH_BYTES: usize = 32 << 20;

/// Where meshes are looked for and how much is embedded.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshOptions {
    /// Directories searched for `package://NAME/...` (a directory NAME inside one, or one
    /// named NAME), after the ancestors of the URDF's directory (ROS_PACKAGE_PATH-style).
    pub search_paths: Vec<PathBuf>,
    /// At most this many bytes of mesh files are embedded; the links whose meshes do not fit
    /// are drawn as the sketch (and the notes say which).
    pub max_bytes: usize,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            search_paths: Vec::new(),
            max_bytes: DEFAULT_MESH_BYTES,
        }
    }
}

/// The visuals found for a robot, and what was not found or not embedded.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Visuals {
    items: Vec<Visual>,
    notes: Vec<String>,
}

#[derive(Clone, Debug, PartialEq)]
struct Visual {
    /// The frame (= link) carrying it, 0 for the base.
    frame: usize,
    /// Placement in R_frame, 4x4 row-major.
    origin: [f64; 16],
    shape: Shape,
    color: Option<[f64; 4]>,
}

#[derive(Clone, Debug, PartialEq)]
enum Shape {
    Stl {
        file: String,
        bytes: Vec<u8>,
        scale: [f64; 3],
    },
    Box([f64; 3]),
    Cylinder {
        radius: f64,
        length: f64,
    },
    Sphere(f64),
}

impl Visuals {
    /// Number of visuals (meshes and shapes) embedded.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether none was found.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Number of meshes embedded and their bytes.
    pub fn meshes(&self) -> (usize, usize) {
        self.items
            .iter()
            .filter_map(|v| match &v.shape {
                Shape::Stl { bytes, .. } => Some(bytes.len()),
                _ => None,
            })
            .fold((0, 0), |(n, b), x| (n + 1, b + x))
    }

    /// What was not found or not embedded (those links are drawn as the sketch).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    pub(crate) fn to_json(&self) -> Value {
        let items: Vec<Value> = self
            .items
            .iter()
            .map(|v| {
                let mut o = json!({ "frame": v.frame, "origin": v.origin, "color": v.color });
                let shape = match &v.shape {
                    Shape::Stl { file, bytes, scale } => json!({
                        "shape": "stl",
                        "file": file,
                        "scale": scale,
                        "data": base64::engine::general_purpose::STANDARD.encode(bytes),
                    }),
                    Shape::Box(size) => json!({ "shape": "box", "size": size }),
                    Shape::Cylinder { radius, length } => {
                        json!({ "shape": "cylinder", "radius": radius, "length": length })
                    }
                    Shape::Sphere(radius) => json!({ "shape": "sphere", "radius": radius }),
                };
                for (k, x) in shape.as_object().into_iter().flatten() {
                    o[k] = x.clone();
                }
                o
            })
            .collect();
        json!({ "items": items, "notes": self.notes })
    }
}

/// The visuals of the links of `robot`, read from the URDF file `urdf` it was loaded from.
/// Meshes are resolved (`package://NAME/...` through the ancestors of the URDF's directory and
/// `options.search_paths`, `file://` and relative paths), STL files embedded up to
/// `options.max_bytes`; other formats (Collada, OBJ) and missing files are listed in the
/// notes and their links drawn as the sketch. Errors: the file cannot be read or is not XML.
pub fn urdf_visuals(robot: &Robot, urdf: &Path, options: &MeshOptions) -> Result<Visuals> {
    let file = urdf.display().to_string();
    let text = std::fs::read_to_string(urdf).map_err(|e| Error::io(file.clone(), e))?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| {
        Error::parse(
            Some(&file),
            e.pos().row as usize,
            format!("invalid XML: {e}"),
        )
    })?;
    let root = doc.root_element();
    let dir = std::fs::canonicalize(urdf)
        .ok()
        .and_then(|p| p.parent().map(Path::to_path_buf))
        .unwrap_or_else(|| PathBuf::from("."));
    let materials: HashMap<&str, [f64; 4]> = elements(root, "material")
        .filter_map(|m| Some((m.attribute("name")?, color(m)?)))
        .collect();
    let placements = link_placements(robot, root);
    let mut out = Visuals::default();
    let mut budget = options.max_bytes;
    for link in elements(root, "link") {
        let name = link.attribute("name").unwrap_or("");
        let Some(&(frame, c)) = placements.get(name) else {
            continue;
        };
        for v in elements(link, "visual") {
            let line = doc.text_pos_at(v.range().start).row;
            let mut note = |s: String| out.notes.push(format!("link `{name}` (line {line}): {s}"));
            let origin = match pose(v) {
                Ok(o) => c.compose(&o),
                Err(e) => {
                    note(e);
                    continue;
                }
            };
            let col = elements(v, "material")
                .next()
                .and_then(|m| color(m).or_else(|| materials.get(m.attribute("name")?).copied()));
            match shape(v, &dir, &options.search_paths, &mut budget) {
                Ok(shape) => out.items.push(Visual {
                    frame,
                    origin: row_major(&origin),
                    shape,
                    color: col,
                }),
                Err(e) => note(format!("{e}: drawn as the sketch")),
            }
        }
    }
    Ok(out)
}

/// Child elements of `n` named `tag`.
fn elements<'a>(
    n: roxmltree::Node<'a, 'a>,
    tag: &'static str,
) -> impl Iterator<Item = roxmltree::Node<'a, 'a>> {
    n.children()
        .filter(move |c| c.is_element() && c.has_tag_name(tag))
}

/// For each URDF link name: the frame carrying it (0 for the root) and C, the URDF link frame
/// in that frame.
fn link_placements(robot: &Robot, root: roxmltree::Node) -> HashMap<String, (usize, Transform)> {
    // URDF link poses at q = 0: the joint origins composed from the root
    let parent: HashMap<String, (String, Transform)> = elements(root, "joint")
        .filter_map(|j| {
            let p = elements(j, "parent").next()?.attribute("link")?;
            let c = elements(j, "child").next()?.attribute("link")?;
            Some((c.to_string(), (p.to_string(), pose(j).ok()?)))
        })
        .collect();
    let pose_of = |link: &str| {
        let (mut t, mut link) = (Transform::identity(), link);
        // (a URDF robodyn loaded is a tree: at most one step per joint)
        for _ in 0..=parent.len() {
            let Some((p, o)) = parent.get(link) else {
                break;
            };
            t = o.compose(&t);
            link = p.as_str();
        }
        t
    };
    let t0 = frame_transforms_per_frame(robot, &vec![0.0; robot.nj()]);
    let mut out: HashMap<String, (usize, Transform)> = HashMap::new();
    for l in elements(root, "link").filter_map(|l| l.attribute("name")) {
        let frame = if parent.contains_key(l) {
            match (1..=robot.nl()).find(|&j| robot.link(j).name == l) {
                Some(j) => j,
                None => continue,
            }
        } else {
            0
        };
        let kk = if frame == 0 {
            Transform::identity()
        } else {
            t0[frame - 1]
        };
        out.insert(l.to_string(), (frame, kk.inverse().compose(&pose_of(l))));
    }
    out
}

/// `<origin xyz rpy>` of an element (identity when absent); rpy = Rz(yaw) Ry(pitch) Rx(roll).
fn pose(n: roxmltree::Node) -> std::result::Result<Transform, String> {
    let Some(o) = elements(n, "origin").next() else {
        return Ok(Transform::identity());
    };
    let xyz = numbers::<3>(o.attribute("xyz"), Some([0.0; 3]), "origin xyz")?;
    let rpy = numbers::<3>(o.attribute("rpy"), Some([0.0; 3]), "origin rpy")?;
    let rot = UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
    Ok(Transform {
        rot: *rot.to_rotation_matrix().matrix(),
        pos: Translation3::new(xyz[0], xyz[1], xyz[2]).vector,
    })
}

/// N numbers of an attribute (`default` when absent, an error without one), finite.
fn numbers<const N: usize>(
    text: Option<&str>,
    default: Option<[f64; N]>,
    what: &str,
) -> std::result::Result<[f64; N], String> {
    let Some(text) = text else {
        return default.ok_or_else(|| format!("{what} is missing"));
    };
    let v: Vec<f64> = text
        .split_whitespace()
        .map(|s| s.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("{what} = `{text}` is not {N} finite numbers"))?;
    v.try_into()
        .map_err(|_| format!("{what} = `{text}` is not {N} numbers"))
}

/// `<color rgba>` of a `<material>`.
fn color(m: roxmltree::Node) -> Option<[f64; 4]> {
    let c = elements(m, "color").next()?;
    numbers::<4>(c.attribute("rgba"), None, "rgba").ok()
}

/// The `<geometry>` of a visual: a primitive shape, or an STL mesh found and within the budget.
fn shape(
    v: roxmltree::Node,
    dir: &Path,
    search: &[PathBuf],
    budget: &mut usize,
) -> std::result::Result<Shape, String> {
    let g = elements(v, "geometry")
        .next()
        .and_then(|g| g.children().find(|c| c.is_element()))
        .ok_or("no <geometry>")?;
    let num = |a: &str| numbers::<1>(g.attribute(a), None, a).map(|[x]| x);
    Ok(match g.tag_name().name() {
        "box" => Shape::Box(numbers::<3>(g.attribute("size"), None, "box size")?),
        "cylinder" => Shape::Cylinder {
            radius: num("radius")?,
            length: num("length")?,
        },
        "sphere" => Shape::Sphere(num("radius")?),
        "mesh" => {
            let uri = g.attribute("filename").ok_or("<mesh> without filename")?;
            let scale = numbers::<3>(g.attribute("scale"), Some([1.0; 3]), "mesh scale")?;
            let path = resolve(uri, dir, search)?;
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
            if !ext.eq_ignore_ascii_case("stl") {
                return Err(format!(
                    "mesh `{uri}`: only STL meshes are embedded (this is `.{ext}`)"
                ));
            }
            let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            if bytes.len() > *budget {
                return Err(format!(
                    "mesh `{uri}` ({} bytes) exceeds what is left of the page's mesh size cap",
                    bytes.len()
                ));
            }
            *budget -= bytes.len();
            Shape::Stl {
                file: uri.to_string(),
                bytes,
                scale,
            }
        }
        other => return Err(format!("unknown geometry <{other}>")),
    })
}

/// The file a mesh URI names: `package://NAME/REST` (a directory NAME among the ancestors of
/// the URDF's directory, beside them, or in `search`), `file://PATH`, or a path relative to the
/// URDF's directory.
fn resolve(uri: &str, dir: &Path, search: &[PathBuf]) -> std::result::Result<PathBuf, String> {
    if let Some(rest) = uri.strip_prefix("package://") {
        let (pkg, rel) = rest
            .trim_start_matches('/')
            .split_once('/')
            .ok_or_else(|| format!("mesh `{uri}`: no package name"))?;
        let named = |d: &Path| d.file_name().is_some_and(|n| n == pkg);
        let candidates = dir.ancestors().chain(search.iter().map(PathBuf::as_path));
        for d in candidates {
            for p in [named(d).then(|| d.join(rel)), Some(d.join(pkg).join(rel))]
                .into_iter()
                .flatten()
            {
                if p.is_file() {
                    return Ok(p);
                }
            }
        }
        return Err(format!(
            "mesh `{uri}` not found (package `{pkg}` looked for among the directories above \
             {} and in the search paths)",
            dir.display()
        ));
    }
    let p = PathBuf::from(uri.strip_prefix("file://").unwrap_or(uri));
    let p = if p.is_absolute() { p } else { dir.join(p) };
    if p.is_file() {
        Ok(p)
    } else {
        Err(format!("mesh `{uri}` not found ({})", p.display()))
    }
}

/// A transformation as a 4x4 row-major array.
fn row_major(t: &Transform) -> [f64; 16] {
    let m: Matrix3<f64> = t.rot;
    let p: Vector3<f64> = t.pos;
    [
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        p.x,
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        p.y,
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)],
        p.z,
        0.0,
        0.0,
        0.0,
        1.0,
    ]
}
