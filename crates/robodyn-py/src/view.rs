//! `robot.view(q=None, trajectory=None)`: the page of `robodyn view` (`robodyn::view`, one
//! self-contained HTML file) as an object Jupyter shows inline (`_repr_html_`, in an iframe) and
//! `.save(path)` writes.

use crate::errors::{InputError, IntoPy};
use crate::robot::Robot;
use pyo3::prelude::*;
use robodyn::view::{self as v, JointColumns, MeshOptions, Pose, Trajectory, ViewOptions};
use std::path::PathBuf;

/// A 3D view of a robot: one HTML page that needs no network and no server.
#[pyclass(module = "robodyn", frozen)]
pub struct View {
    html: String,
    warnings: Vec<String>,
}

#[pymethods]
impl View {
    /// The HTML text of the page.
    #[getter]
    fn html(&self) -> &str {
        &self.html
    }

    /// Loops drawn open at the pose shown, and why (empty when every loop is closed).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// Write the page to `path` (a temporary file beside it renamed over it: a failure never
    /// leaves a partial file).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        v::save(&path, self.html.as_bytes()).py()
    }

    /// The page in an iframe (Jupyter's inline display).
    fn _repr_html_(&self) -> String {
        let doc = self.html.replace('&', "&amp;").replace('"', "&quot;");
        format!(
            "<iframe srcdoc=\"{doc}\" style=\"width: 100%; height: 640px; border: 1px solid \
             #ddd\" sandbox=\"allow-scripts\" title=\"robodyn view\"></iframe>"
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "<robodyn.View: {:.1} MB of HTML>",
            self.html.len() as f64 / 1e6
        )
    }
}

#[pymethods]
impl Robot {
    /// A 3D view of the robot (the page of `robodyn view`): every frame's x and z axes labelled
    /// j, the links along the geometric parameters, revolute and prismatic joints, fixed frames,
    /// cut joints and their twin frames, the base and gravity, URDF meshes (STL) when found.
    ///
    /// `q`: the movable joints (a tree, or a closed robot drawn as given), or a closed robot's
    /// actuated joints (passive joints by loop closure); default q = 0, or a closed robot's
    /// assembly. `trajectory`: a CSV file (column `t` and `q<j>`, or `q_<name>` with
    /// `names="joint"`), or a pair `(t, Q)` with one row of Q per time over the movable joints
    /// (a closed robot: its actuated joints). Returns a `View` (`.save(path)`, shown inline in
    /// Jupyter).
    #[pyo3(signature = (q=None, trajectory=None, names="frame"))]
    fn view(
        &self,
        q: Option<Vec<f64>>,
        trajectory: Option<&Bound<'_, PyAny>>,
        names: &str,
    ) -> PyResult<View> {
        let robot = self.model();
        let columns = match names {
            "frame" => JointColumns::Frame,
            "joint" => JointColumns::Joint,
            _ => {
                return Err(InputError::new_err(format!(
                    "names = {names:?}: expected \"frame\" (q<j>) or \"joint\" (q_<name>)"
                )))
            }
        };
        let pose = match q {
            None => Pose::Default,
            Some(q) if !robot.is_tree() && q.len() == robot.actuated_joints().len() => {
                Pose::Actuated(q)
            }
            Some(q) => Pose::Tree(q),
        };
        let trajectory = match trajectory {
            None => None,
            Some(t) => Some(if let Ok(path) = t.extract::<PathBuf>() {
                let table = robodyn::io::table::Table::read(&path).py()?;
                Trajectory::from_table(&robot, &table, columns).py()?
            } else {
                let (t, rows): (Vec<f64>, Vec<Vec<f64>>) = t.extract().map_err(|_| {
                    InputError::new_err(
                        "trajectory: a CSV file's path, or a pair (t, Q) with one row of Q per time",
                    )
                })?;
                Trajectory::from_samples(&robot, &t, &rows, columns).py()?
            }),
        };
        let visuals = match &self.source {
            Some(p)
                if matches!(
                    robodyn::io::Format::from_path(p),
                    Ok(robodyn::io::Format::Urdf)
                ) =>
            {
                let search = std::env::var_os("ROS_PACKAGE_PATH")
                    .map(|r| std::env::split_paths(&r).collect())
                    .unwrap_or_default();
                let options = MeshOptions {
                    search_paths: search,
                    ..MeshOptions::default()
                };
                Some(v::urdf_visuals(&robot, p, &options).py()?)
            }
            _ => None,
        };
        let options = ViewOptions {
            pose,
            trajectory,
            visuals,
            picture: None,
        };
        let page = v::page(&robot, &options).py()?;
        Ok(View {
            html: page.html,
            warnings: page.warnings,
        })
    }
}
