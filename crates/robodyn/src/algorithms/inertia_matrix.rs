//! Inertia matrix A(q) of a tree robot by the composite-link method and the vector H(q, qd) by
//! Newton–Euler with qdd = 0 (§10.2.3, which applies the two methods of the book's §9.7 to trees):
//! Gamma = A(q) qdd + H(q, qd).
//!
//! The checked functions ([`inertia_matrix`], [`h_vector`] and their `_into` forms) work over
//! the movable joints ([`Robot::coordinates`]). The kernel [`composite_inertia_matrix`] fills
//! the NL x NL matrix of the tree arrays (joint j at index j-1; rows and columns of fixed frames
//! zero). A_ij = 0 whenever neither of i, j is an ancestor of the other, and the rotor inertia
//! Ia_j is on the diagonal. Written once over [`DynScalar`]: the symbolic generator runs it on
//! expressions.

use crate::algorithms::inverse_dynamics::{check_state, rnea_with_environment, tree_vector_map};
use crate::data::Data;
use crate::error::Result;
use crate::model::{inertia_to_antecedent, DynModel, Environment, JointType, Robot};
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// Composite links (backward recursion j = NL..1): jJ^c, jMS^c, M^c of every link about its own
/// origin, and iA_j, iP_j, in the buffers of `ws` (kernel, tree array q).
///
/// Composite link k is moved to its antecedent by [`inertia_to_antecedent`] (parallel-axis
/// theorem).
pub fn composite_links<T: DynScalar>(model: &DynModel<T>, ws: &mut Data<T>, q: &[T]) {
    for j in 1..=model.nl {
        let (rot, pos) = model.frame(j).transform(&q[j - 1]);
        ws.rot[j] = rot;
        ws.pos[j] = pos;
        let l = model.link(j);
        ws.jc[j] = l.inertia.clone();
        ws.msc[j] = l.ms.clone();
        ws.mc[j] = l.mass.clone();
    }
    for k in (1..=model.nl).rev() {
        // composite link k is complete (its successors, numbered after it, are in)
        name_composite(model, ws, k);
        let i = model.frame(k).ant;
        if i == 0 {
            continue;
        }
        let (jk, ms) =
            inertia_to_antecedent(&ws.rot[k], &ws.pos[k], &ws.jc[k], &ws.msc[k], &ws.mc[k]);
        let mk = ws.mc[k].clone();
        ws.jc[i] += jk;
        ws.msc[i] += ms;
        ws.mc[i] += mk;
    }
}

/// Inertia matrix A(q) (NL x NL, tree arrays) by the composite-link method: the generic kernel,
/// allocation-free.
///
/// Column j: the wrench on the composite link j for qdd = e_j (qd = 0, g = 0) is
/// f = z x MS^c, m = J^c z (revolute) or f = M^c z, m = MS^c x z (prismatic); A_jj is its
/// projection on the joint axis plus Ia_j, and A_ij (= A_ji) for every ancestor i of j is the
/// projection after transporting the wrench to R_i (eqs 10.10–10.12 with the link terms zero).
pub fn composite_inertia_matrix<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    q: &[T],
    a: &mut DMatrix<T>,
) {
    let n = model.nl;
    assert_eq!(a.shape(), (n, n), "A must be NL x NL");
    composite_links(model, ws, q);
    a.fill(T::zero());
    for j in 1..=n {
        let fr = model.frame(j);
        let ms = &ws.msc[j];
        let (mut f, mut m) = match fr.joint {
            JointType::Revolute => (
                Vector3::new(-ms.y.clone(), ms.x.clone(), T::zero()),
                ws.jc[j].column(2).into_owned(),
            ),
            JointType::Prismatic => (
                Vector3::new(T::zero(), T::zero(), ws.mc[j].clone()),
                Vector3::new(ms.y.clone(), -ms.x.clone(), T::zero()),
            ),
            JointType::Fixed => continue,
        };
        a[(j - 1, j - 1)] = project(fr.joint, &f, &m) + model.link(j).ia.clone();
        let mut k = j;
        while model.frame(k).ant != 0 {
            let fi = &ws.rot[k] * &f;
            m = &ws.rot[k] * &m + ws.pos[k].cross(&fi);
            f = fi;
            k = model.frame(k).ant;
            if T::NAMED {
                // the wrench of column j carried to link k: named, or it would grow with the
                // depth of the tree
                // (by the description's link numbers)
                let (lk, lj) = (model.wrench_link(k), model.wrench_link(j));
                f = f.map_with_location(|c, _, x| x.named(|| format!("AF{}_{lk}_{lj}", c + 1)));
                m = m.map_with_location(|c, _, x| x.named(|| format!("AN{}_{lk}_{lj}", c + 1)));
            }
            let joint = model.frame(k).joint;
            if joint.is_movable() {
                let v = project(joint, &f, &m);
                a[(k - 1, j - 1)] = v.clone();
                a[(j - 1, k - 1)] = v;
            }
        }
    }
}

/// Naming hook of the customized symbolic model: the composite inertia of link k (`JP<r><c><k>`,
/// `MSP<c><k>`, `MP<k>`), so that its expression does not grow with the size of the subtree. A
/// no-op for `f64`.
#[inline(always)]
fn name_composite<T: DynScalar>(model: &DynModel<T>, ws: &mut Data<T>, k: usize) {
    if !T::NAMED {
        return;
    }
    // names carry the description's link number
    let n = model.wrench_link(k);
    let j = ws.jc[k].clone();
    ws.jc[k] = Matrix3::from_fn(|r, c| {
        let (r, c) = (r.min(c), r.max(c));
        j[(r, c)]
            .clone()
            .named(|| format!("JP{}{}{n}", r + 1, c + 1))
    });
    let ms = ws.msc[k].clone();
    ws.msc[k] = Vector3::from_fn(|c, _| ms[c].clone().named(|| format!("MSP{}{n}", c + 1)));
    ws.mc[k] = ws.mc[k].clone().named(|| format!("MP{n}"));
}

#[inline]
fn project<T: DynScalar>(joint: JointType, f: &Vector3<T>, m: &Vector3<T>) -> T {
    match joint {
        JointType::Revolute => m.z.clone(),
        JointType::Prismatic => f.z.clone(),
        JointType::Fixed => T::zero(),
    }
}

/// Inertia matrix A(q) into `a` (N x N over the movable joints, frame order; kg m², kg, and
/// kg m for the coupling of a revolute and a prismatic joint) by composite links, rotor inertias
/// on the diagonal. `q` over the movable joints (rad, m). Allocation-free.
pub fn inertia_matrix_into(
    robot: &Robot,
    data: &mut Data,
    q: &[f64],
    a: &mut DMatrix<f64>,
) -> Result<()> {
    check_state(robot, data, ["q", "q", "q"], [q, q, q])?;
    let c = robot.coordinates();
    let n = c.len();
    if a.shape() != (n, n) {
        return Err(crate::Error::dimension(
            "A",
            n * n,
            a.len(),
            format!("{n} x {n} over {}", c.describe("movable joints")),
        ));
    }
    // the model of the dynamic recursions: its A is the matrix over the movable joints
    composite_inertia_matrix(robot.dynamic(), data, q, a);
    Ok(())
}

/// A(q) (N x N over the movable joints); checks its input and allocates.
pub fn inertia_matrix(robot: &Robot, q: &[f64]) -> Result<DMatrix<f64>> {
    let mut data = Data::new(robot);
    let n = robot.dof();
    let mut a = DMatrix::zeros(n, n);
    inertia_matrix_into(robot, &mut data, q, &mut a)?;
    Ok(a)
}

/// H(q, qd) into `h` (movable joints): centrifugal, Coriolis, gravity, friction and
/// external-wrench torques under `env`, i.e. the Newton–Euler torques with qdd = 0 (§9.7 method
/// 1), so that Gamma = A(q) qdd + H(q, qd). Allocation-free.
pub fn h_vector_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    h: &mut [f64],
) -> Result<()> {
    let names = ["q", "qd", "qd"];
    tree_vector_map(
        robot,
        data,
        env,
        names,
        [q, qd, qd],
        "H",
        h,
        |m, d, q, qd, _, t| {
            let z = std::mem::take(&mut d.zeros);
            rnea_with_environment(m, d, env, q, qd, &z, t);
            d.zeros = z;
        },
    )
}

/// H(q, qd) over the movable joints with the robot's environment; allocates.
pub fn h_vector(robot: &Robot, q: &[f64], qd: &[f64]) -> Result<DVector<f64>> {
    let mut data = Data::new(robot);
    let mut h = DVector::zeros(robot.dof());
    h_vector_into(
        robot,
        &mut data,
        robot.environment(),
        q,
        qd,
        h.as_mut_slice(),
    )?;
    Ok(h)
}
