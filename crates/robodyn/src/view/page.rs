//! The HTML page: the template, the vendored three.js modules as `data:` URLs of an import map,
//! the scene as JSON and the page's own script.

use super::scene::scene;
use super::ViewOptions;
use crate::error::{Error, Result};
use crate::Robot;
use base64::Engine as _;
use std::path::Path;

/// The page's layout and styles, with the markers `@TITLE@`, `@IMPORTMAP@`, `@SCENE@`,
/// `@STYLE@` and `@SCRIPT@`.
const TEMPLATE: &str = include_str!("assets/page.html");
const STYLE: &str = include_str!("assets/viewer.css");
const SCRIPT: &str = include_str!("assets/viewer.js");

/// The vendored modules (three.js r170, MIT: `assets/three/README.md`), by import specifier.
const MODULES: [(&str, &str); 4] = [
    ("three", include_str!("assets/three/three.module.min.js")),
    (
        "three/addons/OrbitControls.js",
        include_str!("assets/three/OrbitControls.js"),
    ),
    (
        "three/addons/CSS2DRenderer.js",
        include_str!("assets/three/CSS2DRenderer.js"),
    ),
    (
        "three/addons/STLLoader.js",
        include_str!("assets/three/STLLoader.js"),
    ),
];

/// The license notice carried in the page next to the embedded three.js.
const THREE_NOTICE: &str = "three.js r170 (npm three@0.170.0), Copyright © 2010-2024 three.js \
authors, MIT License: https://github.com/mrdoob/three.js/blob/r170/LICENSE";

/// A page and what its reader should know.
#[derive(Clone, Debug, PartialEq)]
pub struct Page {
    /// The HTML text.
    pub html: String,
    /// Loops that are not closed at the pose shown, and why (they are drawn open).
    pub warnings: Vec<String>,
}

impl Page {
    /// Write the page to `path` ([`save`]).
    pub fn save(&self, path: &Path) -> Result<()> {
        save(path, self.html.as_bytes())
    }
}

/// Write `bytes` to the file `path` without ever leaving a partial file in place of the old
/// one: a regular file (or a new one) is written as a temporary file in the same directory,
/// then renamed over it; a symbolic link is followed (its target is replaced the same way); a
/// path that exists and is not a regular file (`/dev/stdout`, a named pipe) is written in
/// place, never replaced.
pub fn save(path: &Path, bytes: &[u8]) -> Result<()> {
    let err = |p: &Path, e| Error::io(p.display().to_string(), e);
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => {
            let target = std::fs::canonicalize(path).map_err(|e| err(path, e))?;
            return save(&target, bytes);
        }
        Ok(m) if !m.is_file() => return std::fs::write(path, bytes).map_err(|e| err(path, e)),
        _ => {}
    }
    let name = path
        .file_name()
        .map_or_else(|| "page".into(), |n| n.to_string_lossy().into_owned());
    let tmp = path.with_file_name(format!(".{name}.robodyn-{}.tmp", std::process::id()));
    std::fs::write(&tmp, bytes)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            err(path, e)
        })
}

/// The self-contained HTML page showing `robot` (see the [module](super) documentation).
/// Errors: the pose or the trajectory does not fit the robot, loop closure fails at a given
/// actuated pose. A closed robot whose assembly cannot be closed is drawn with its loops open,
/// with a warning.
pub fn page(robot: &Robot, options: &ViewOptions) -> Result<Page> {
    let (scene, warnings) = scene(robot, options)?;
    let mut html = String::with_capacity(TEMPLATE.len() + 1_500_000);
    let mut rest = TEMPLATE;
    while let Some(start) = rest.find('@') {
        let Some(len) = rest[start + 1..].find('@') else {
            break;
        };
        let marker = &rest[start + 1..start + 1 + len];
        let value = match marker {
            "TITLE" => escape_html(&format!("{} — robodyn view", robot.name())),
            "NOTICE" => THREE_NOTICE.to_string(),
            "IMPORTMAP" => import_map(),
            "SCENE" => script_json(&scene.to_string()),
            "STYLE" => STYLE.to_string(),
            "SCRIPT" => SCRIPT.to_string(),
            _ => {
                html.push_str(&rest[..start + 1]);
                rest = &rest[start + 1..];
                continue;
            }
        };
        html.push_str(&rest[..start]);
        html.push_str(&value);
        rest = &rest[start + len + 2..];
    }
    html.push_str(rest);
    Ok(Page { html, warnings })
}

/// `{"imports": {"three": "data:text/javascript;base64,...", ...}}`: every module embedded, so
/// that the page needs no network and no server (a `file://` page cannot import files).
fn import_map() -> String {
    let imports: serde_json::Map<String, serde_json::Value> = MODULES
        .iter()
        .map(|(name, code)| {
            let b64 = base64::engine::general_purpose::STANDARD.encode(code);
            (
                name.to_string(),
                format!("data:text/javascript;base64,{b64}").into(),
            )
        })
        .collect();
    serde_json::json!({ "imports": imports }).to_string()
}

/// JSON inside a `<script>` element: `<` written as `\u003c` (only inside strings, where JSON
/// allows it), so that no `</script>` or `<!--` in a name ends or changes the element.
fn script_json(json: &str) -> String {
    json.replace('<', "\\u003c")
}

/// Text for HTML element content.
fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn script_json_cannot_close_the_script_element() {
        let s = serde_json::json!({ "robot": "a</script><script>alert(1)</script>" }).to_string();
        let out = script_json(&s);
        assert!(!out.contains("</"));
        let back: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(back["robot"], "a</script><script>alert(1)</script>");
    }
}
