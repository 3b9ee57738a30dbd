//! The parameters identified: the robot's base parameters (as `base-params` defines them), the
//! drive parameters of the motors when a transmission couples joints, and a constant torque
//! offset per joint when asked.
//!
//! With a transmission m = R q_a, motor k's rotor inertia Ia_k, viscous and Coulomb friction
//! Fv_k, Fs_k (motor units, stored as IA, FV, FS of link `joints[k]`) add
//! tau = R^T (Ia m_dd + Fv m_d + Fs sign(m_d)) to the joint torques: column k of each appears
//! in every joint row where R's row k is nonzero (the TX40's motor 6 in joints 5 and 6). Those
//! columns are appended to the base parameters of the links and reduced the same way as the
//! numerical method reduces K (an unpivoted QR in order over random consistent states: a motor
//! column in the span of the columns before it is grouped into them, e.g. the rotor of a first
//! vertical axis into ZZR1 with the factor R_11^2).

use super::model_access::{coulomb_sign, BaseSet, ModelAccess, Rotors};
use crate::algorithms::base_parameters::numeric::format_coefficient;
use crate::algorithms::regressor::PARAMS_PER_LINK;
use crate::error::{Error, Result};
use crate::model::param::{FS, FV, IA};
use faer::linalg::solvers::SolveLstsq;
use faer::Mat;

/// What an identified parameter is.
#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    /// Base parameter number r of the base set.
    Base(usize),
    /// Drive parameter (`IA`, `FS` or `FV` index) of motor k (transmission).
    Motor {
        /// Motor k (0-based, in the transmission's order).
        motor: usize,
        /// `IA`, `FS` or `FV` index within a link's 13 standard parameters.
        which: usize,
    },
    /// Joint-side drive parameter (`IA`, `FS` or `FV` index) of actuated joint k (0-based):
    /// with a transmission, the inertia and friction on the joint side of the gears, acting on
    /// q_k alone (IA_k qdd_k + FV_k qd_k + FS_k sign(qd_k) in joint k's torque), next to the
    /// motors'.
    Joint {
        /// Actuated joint k (0-based, in the transmission's order).
        joint: usize,
        /// `IA`, `FS` or `FV` index within a link's 13 standard parameters.
        which: usize,
    },
    /// Constant torque offset of actuated joint number k (0-based).
    Offset(usize),
}

impl Kind {
    /// Whether the parameter is not a combination of the robot's standard parameters (an
    /// offset, a joint-side drive parameter of a transmission): a free variable of the fit.
    pub fn is_free(&self) -> bool {
        matches!(self, Kind::Offset(_) | Kind::Joint { .. })
    }
}

/// One identified parameter.
#[derive(Clone, Debug)]
pub struct Parameter {
    /// Display name: the standard parameter's (`ZZ1`), `R` before the link number when grouped
    /// (`XXR2`), `OFF<j>` for the offset of joint j.
    pub name: String,
    /// Grouping equation (right-hand side), in standard parameters.
    pub equation: String,
    /// What it is.
    pub kind: Kind,
}

/// How the parameter vector is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterOptions {
    /// Which rotor inertias IA are parameters.
    pub rotors: Rotors,
    /// Coulomb and viscous friction FS, FV of the actuated joints are parameters.
    pub friction: bool,
    /// A constant torque offset per actuated joint is a parameter.
    pub offsets: bool,
    /// With a transmission: the joint-side rotor inertia (when rotors are identified) and
    /// friction (when friction is) of each actuated joint as parameters next to the motors',
    /// those a motor's column already spans left out (the TX40 keeps joint 6's: motor 6 turns
    /// with q5 + q6). No effect without a transmission.
    pub joint_drives: bool,
    /// Seed of the random states of the numerical base-parameter method.
    pub seed: u64,
}

impl Default for ParameterOptions {
    fn default() -> Self {
        ParameterOptions {
            rotors: Rotors::Actuated,
            friction: true,
            offsets: false,
            joint_drives: true,
            seed: 1,
        }
    }
}

/// The identification model X: x = map K (+ offsets), rows of W at each sample.
#[derive(Clone, Debug)]
pub struct ParameterModel {
    /// The identified parameters, in the order of x.
    pub params: Vec<Parameter>,
    /// The base set of the robot's standard parameters (numerical method).
    pub base: BaseSet,
    /// `x_r = sum_c map[r][c].1 K[map[r][c].0]` for the base and motor parameters (empty for
    /// offsets).
    pub map: Vec<Vec<(usize, f64)>>,
    /// Number of standard parameters (13 NL).
    pub standard_count: usize,
    /// Transmission R (N x N) when given.
    pub transmission: Option<Vec<Vec<f64>>>,
    /// Link (frame number) of each motor (the transmission's joints).
    pub motor_links: Vec<usize>,
    /// Actuated joints (rows of W per sample).
    pub joints: Vec<usize>,
    /// Dead band of the Coulomb sign in the rows (rad/s or m/s of the joint; a motor's velocity
    /// divided by its largest gear ratio): see [`coulomb_sign`]. 0 (the default): the exact
    /// sign.
    pub coulomb_band: f64,
    n: usize,
    /// Scratch: rows of the library's base columns at one sample.
    base_rows: Vec<f64>,
    tau_e: Vec<f64>,
}

/// Relative tolerance on |R_kk| of the unit-column QR that groups a motor column.
const GROUP_TOLERANCE: f64 = 1e-9;

impl ParameterModel {
    /// Build the parameter vector of `access`'s robot.
    pub fn build(access: &mut ModelAccess, opt: &ParameterOptions) -> Result<ParameterModel> {
        let joints = access.actuated_joints().to_vec();
        let n = joints.len();
        let transmission = access.transmission().map(|t| t.matrix.clone());
        // with a transmission the library's selection has no drive parameters: they are the
        // motors' and are appended below
        let (rotors, friction) = if transmission.is_some() {
            (Rotors::None, false)
        } else {
            (opt.rotors, opt.friction)
        };
        let base = access.base_parameters(rotors, friction, opt.seed)?;
        let nl = access.nl();
        let mut params: Vec<Parameter> = base
            .names
            .iter()
            .zip(&base.equations)
            .enumerate()
            .map(|(r, (name, eq))| Parameter {
                name: name.clone(),
                equation: eq.clone(),
                kind: Kind::Base(r),
            })
            .collect();
        let mut map: Vec<Vec<(usize, f64)>> = (0..base.base.len())
            .map(|r| {
                std::iter::once((base.base[r], 1.0))
                    .chain(
                        base.grouped
                            .iter()
                            .enumerate()
                            .filter(|(c, _)| base.beta[(r, *c)] != 0.0)
                            .map(|(c, &g)| (g, base.beta[(r, c)])),
                    )
                    .collect()
            })
            .collect();
        let mut model = ParameterModel {
            params: Vec::new(),
            base_rows: vec![0.0; n * base.base.len()],
            tau_e: vec![0.0; n],
            base,
            map: Vec::new(),
            standard_count: PARAMS_PER_LINK * nl,
            transmission: transmission.clone(),
            motor_links: joints.clone(),
            joints: joints.clone(),
            coulomb_band: 0.0,
            n,
        };
        if let Some(r) = &transmission {
            check_transmission(r, n)?;
            let mut wanted = Vec::new();
            let mut which_drives = Vec::new();
            if opt.rotors != Rotors::None {
                which_drives.push(IA);
            }
            if opt.friction {
                which_drives.extend([FS, FV]);
            }
            for k in 0..n {
                wanted.extend(
                    which_drives
                        .iter()
                        .map(|&w| Kind::Motor { motor: k, which: w }),
                );
            }
            if opt.joint_drives {
                for k in 0..n {
                    wanted.extend(
                        which_drives
                            .iter()
                            .map(|&w| Kind::Joint { joint: k, which: w }),
                    );
                }
            }
            let (kept, grouped) = model.reduce_motor_columns(access, &wanted, opt.seed)?;
            for kind in kept {
                let (k, which) = match kind {
                    Kind::Joint { joint, which } => {
                        let name = format!("{}J{}", DRIVE_NAMES[drive_slot(which)], joints[joint]);
                        params.push(Parameter {
                            equation: format!(
                                "joint-side {} of joint {}",
                                DRIVE_WORDS[drive_slot(which)],
                                joints[joint]
                            ),
                            name,
                            kind,
                        });
                        map.push(Vec::new());
                        continue;
                    }
                    Kind::Motor { motor, which } => (motor, which),
                    _ => unreachable!("drive columns"),
                };
                let j = joints[k];
                let index = PARAMS_PER_LINK * (j - 1) + which;
                params.push(Parameter {
                    name: access.standard_name(index),
                    equation: access.standard_name(index),
                    kind: Kind::Motor { motor: k, which },
                });
                map.push(vec![(index, 1.0)]);
            }
            // grouped motor parameters: x_r += coef K_motor in the parameters they join (a
            // joint-side column a motor's spans is left out: the motor's parameter stands for it)
            for (kind, coefs) in grouped {
                let Kind::Motor { motor: k, which } = kind else {
                    continue;
                };
                let index = PARAMS_PER_LINK * (joints[k] - 1) + which;
                for (r, c) in coefs {
                    map[r].push((index, c));
                    let mag = format_coefficient(c.abs());
                    let sign = if c < 0.0 { " - " } else { " + " };
                    let term = if mag == "1" {
                        access.standard_name(index)
                    } else {
                        format!("{mag}*{}", access.standard_name(index))
                    };
                    params[r].equation.push_str(&format!("{sign}{term}"));
                    if !params[r].name.contains('R') {
                        params[r].name = grouped_name(&params[r].name);
                    }
                }
            }
        }
        if opt.offsets {
            for (k, &j) in joints.iter().enumerate() {
                params.push(Parameter {
                    name: format!("OFF{j}"),
                    equation: format!("constant torque offset of joint {j}"),
                    kind: Kind::Offset(k),
                });
                map.push(Vec::new());
            }
        }
        model.params = params;
        model.map = map;
        Ok(model)
    }

    /// Number of identified parameters p.
    pub fn count(&self) -> usize {
        self.params.len()
    }

    /// Rows per sample N.
    pub fn joints_count(&self) -> usize {
        self.n
    }

    /// Display names of the parameters, in the order of x.
    pub fn names(&self) -> Vec<String> {
        self.params.iter().map(|p| p.name.clone()).collect()
    }

    /// x for standard parameters `k` (13 per link); offsets zero.
    pub fn values(&self, k: &[f64]) -> Vec<f64> {
        self.map
            .iter()
            .map(|terms| terms.iter().map(|(i, c)| c * k[*i]).sum())
            .collect()
    }

    /// Standard parameters reproducing `x` with every other standard parameter zero (the base
    /// robot of `base-params --write-robot`): `K[base_r] = x_r`, `K[motor] = x_motor`.
    pub fn base_robot_parameters(&self, x: &[f64]) -> Vec<f64> {
        let mut k = vec![0.0; self.standard_count];
        for (p, v) in self.params.iter().zip(x) {
            match p.kind {
                Kind::Base(r) => k[self.base.base[r]] = *v,
                Kind::Motor { motor, which } => {
                    k[PARAMS_PER_LINK * (self.motor_links[motor] - 1) + which] = *v
                }
                Kind::Offset(_) | Kind::Joint { .. } => {}
            }
        }
        k
    }

    /// Offsets in x by actuated joint (zero when not identified).
    pub fn offsets(&self, x: &[f64]) -> Vec<f64> {
        let mut o = vec![0.0; self.n];
        for (p, v) in self.params.iter().zip(x) {
            if let Kind::Offset(k) = p.kind {
                o[k] = *v;
            }
        }
        o
    }

    /// Motor-joint drive columns of motor k at (qd_a, qdd_a): the joint torques of unit Ia_k,
    /// Fs_k or Fv_k, R_k^T (R_k qdd), R_k^T s(R_k qd), R_k^T (R_k qd), with s the Coulomb sign of
    /// dead band `band` times the motor's largest gear ratio max_j |R_kj| (the band is stated on
    /// the joint side).
    fn motor_column(
        r: &[Vec<f64>],
        k: usize,
        which: usize,
        (qd, qdd): (&[f64], &[f64]),
        band: f64,
        out: &mut [f64],
    ) {
        let row = &r[k];
        let dot = |v: &[f64]| row.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let s = match which {
            IA => dot(qdd),
            FV => dot(qd),
            _ => {
                let ratio = row.iter().fold(0.0f64, |m, a| m.max(a.abs()));
                coulomb_sign(dot(qd), band * ratio)
            }
        };
        for (o, a) in out.iter_mut().zip(row) {
            *o = a * s;
        }
    }

    /// The column of a drive parameter (motor or joint side) at (qd_a, qdd_a): for a motor,
    /// [`ParameterModel::motor_column`]; for joint k's own, qdd_k, sign(qd_k) (dead band
    /// `band`) or qd_k in row k only.
    fn drive_column(
        r: &[Vec<f64>],
        kind: &Kind,
        (qd, qdd): (&[f64], &[f64]),
        band: f64,
        out: &mut [f64],
    ) {
        match *kind {
            Kind::Motor { motor, which } => {
                Self::motor_column(r, motor, which, (qd, qdd), band, out)
            }
            Kind::Joint { joint, which } => {
                out.fill(0.0);
                out[joint] = match which {
                    IA => qdd[joint],
                    FV => qd[joint],
                    _ => coulomb_sign(qd[joint], band),
                };
            }
            _ => unreachable!("drive columns"),
        }
    }

    /// Which motor columns are independent of the link base parameters and of the motor
    /// columns before them (kept), and the coefficients of the others over the kept columns
    /// (base parameter r, or motor parameter after the base ones).
    #[allow(clippy::type_complexity)]
    fn reduce_motor_columns(
        &self,
        access: &mut ModelAccess,
        wanted: &[Kind],
        seed: u64,
    ) -> Result<(Vec<Kind>, Vec<(Kind, Vec<(usize, f64)>)>)> {
        let r = self.transmission.as_ref().expect("transmission");
        let nb = self.base.base.len();
        let total = nb + wanted.len();
        let samples = (3 * total).div_ceil(self.n).max(20);
        let states = access.sample_rows(samples, seed ^ 0x5eed, &self.base.base)?;
        let rows = samples * self.n;
        let mut w = Mat::<f64>::zeros(rows, total);
        let mut col = vec![0.0; self.n];
        for (s, ([_, qd, qdd], base_rows)) in states.iter().enumerate() {
            for i in 0..self.n {
                for c in 0..nb {
                    w[(s * self.n + i, c)] = base_rows[i * nb + c];
                }
            }
            for (c, kind) in wanted.iter().enumerate() {
                Self::drive_column(r, kind, (qd, qdd), 0.0, &mut col);
                for i in 0..self.n {
                    w[(s * self.n + i, nb + c)] = col[i];
                }
            }
        }
        // a motor column is kept when its distance from the span of the columns kept before it
        // (relative to its norm) is above the tolerance: the definition of |R_kk| of an
        // unpivoted QR, computed by projection because a QR's diagonal stops meaning that once
        // one exactly dependent column has been met
        let column = |c: usize| Mat::from_fn(rows, 1, |i, _| w[(i, c)]);
        let mut kept_cols: Vec<usize> = (0..nb).collect();
        let mut kept = Vec::new();
        let mut grouped = Vec::new();
        for (c, m) in wanted.iter().cloned().enumerate() {
            let b = column(nb + c);
            let norm = (0..rows).map(|i| b[(i, 0)] * b[(i, 0)]).sum::<f64>().sqrt();
            if norm == 0.0 {
                grouped.push((m, Vec::new()));
                continue;
            }
            let a = Mat::from_fn(rows, kept_cols.len(), |i, k| w[(i, kept_cols[k])]);
            let x = a.qr().solve_lstsq(&b);
            let residual = (0..rows)
                .map(|i| {
                    let fit: f64 = (0..kept_cols.len()).map(|k| a[(i, k)] * x[(k, 0)]).sum();
                    (b[(i, 0)] - fit).powi(2)
                })
                .sum::<f64>()
                .sqrt();
            if std::env::var("ROBODYN_DEBUG").is_ok() {
                eprintln!(
                    "drive column {m:?}: relative distance {:e}",
                    residual / norm
                );
            }
            if residual > GROUP_TOLERANCE * norm {
                kept_cols.push(nb + c);
                kept.push(m);
            } else {
                // kept motor columns come after the base parameters, in `kept` order
                // coefficients whose contribution is at rounding level are dropped
                let col_norm =
                    |k: usize| (0..rows).map(|i| a[(i, k)] * a[(i, k)]).sum::<f64>().sqrt();
                grouped.push((
                    m,
                    (0..kept_cols.len())
                        .map(|k| (k, x[(k, 0)]))
                        .filter(|&(k, v)| (v * col_norm(k)).abs() > 1e-10 * norm)
                        .collect(),
                ));
            }
        }
        Ok((kept, grouped))
    }

    /// Rows of W (N x p, row-major) and the torques of the external wrenches at one sample of
    /// the actuated joints.
    pub fn rows(
        &mut self,
        access: &mut ModelAccess,
        qa: &[f64],
        qda: &[f64],
        qdda: &[f64],
        out: &mut [f64],
        tau_e: &mut [f64],
    ) -> Result<()> {
        let (n, p, nb) = (self.n, self.params.len(), self.base.base.len());
        access.rows(
            qa,
            qda,
            qdda,
            &self.base.base,
            self.coulomb_band,
            &mut self.base_rows,
            &mut self.tau_e,
        )?;
        tau_e.copy_from_slice(&self.tau_e);
        let mut col = vec![0.0; n];
        for i in 0..n {
            out[i * p..i * p + nb].copy_from_slice(&self.base_rows[i * nb..(i + 1) * nb]);
        }
        for (c, prm) in self.params.iter().enumerate().skip(nb) {
            match prm.kind {
                Kind::Motor { .. } | Kind::Joint { .. } => {
                    let r = self.transmission.as_ref().expect("transmission");
                    let band = self.coulomb_band;
                    Self::drive_column(r, &prm.kind, (qda, qdda), band, &mut col);
                    for i in 0..n {
                        out[i * p + c] = col[i];
                    }
                }
                Kind::Offset(k) => {
                    for i in 0..n {
                        out[i * p + c] = if i == k { 1.0 } else { 0.0 };
                    }
                }
                Kind::Base(_) => unreachable!("base parameters come first"),
            }
        }
        Ok(())
    }

    /// Joint-side drive parameters for a model without transmission (IA, FS, FV of each
    /// actuated joint) from standard parameters whose IA, FS, FV are motors' (transmission):
    /// the diagonal of R^T diag(Ia) R for the inertia and viscous friction, sum |R_kj| Fs_k for
    /// the Coulomb friction. Exact when R is diagonal; the coupling terms are dropped otherwise.
    pub fn joint_side_drives(&self, k: &[f64]) -> Vec<f64> {
        let mut out = k.to_vec();
        let Some(r) = &self.transmission else {
            return out;
        };
        for (c, &j) in self.joints.iter().enumerate() {
            let mut v = [0.0; 3];
            for (m, row) in r.iter().enumerate() {
                let base = PARAMS_PER_LINK * (self.motor_links[m] - 1);
                v[0] += row[c] * row[c] * k[base + IA];
                v[1] += row[c].abs() * k[base + FS];
                v[2] += row[c] * row[c] * k[base + FV];
            }
            let base = PARAMS_PER_LINK * (j - 1);
            out[base + IA] = v[0];
            out[base + FS] = v[1];
            out[base + FV] = v[2];
        }
        out
    }
}

/// The drive parameters' names (joint-side `FVJ6`), by [`drive_slot`].
const DRIVE_NAMES: [&str; 3] = ["IA", "FS", "FV"];

/// The drive parameters in words, by [`drive_slot`].
const DRIVE_WORDS: [&str; 3] = ["rotor inertia", "Coulomb friction", "viscous friction"];

/// 0, 1, 2 for `IA`, `FS`, `FV`.
fn drive_slot(which: usize) -> usize {
    match which {
        IA => 0,
        FS => 1,
        _ => 2,
    }
}

/// `XX2` -> `XXR2`.
fn grouped_name(name: &str) -> String {
    match name.find(|c: char| c.is_ascii_digit()) {
        Some(k) => format!("{}R{}", &name[..k], &name[k..]),
        None => name.to_string(),
    }
}

fn check_transmission(r: &[Vec<f64>], n: usize) -> Result<()> {
    let m = Mat::from_fn(n, n, |i, j| r[i][j]);
    let sv = m
        .singular_values()
        .map_err(|e| Error::Numerical(format!("SVD of the transmission failed: {e:?}")))?;
    if sv[n - 1].is_nan() || sv[n - 1] <= 1e-12 * sv[0] {
        return Err(Error::Input(
            "the transmission matrix R is singular: motor positions must determine the joint \
             positions"
                .into(),
        ));
    }
    Ok(())
}
