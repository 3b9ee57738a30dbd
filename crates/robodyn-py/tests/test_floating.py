"""Floating-base robots from Python (issue 27): `robodyn.load(urdf, floating=True)` and the model
functions on nq / nv vectors.

Cross-checks against Pinocchio with a free-flyer root (`buildModelFromUrdf(path,
JointModelFreeFlyer())`, the joints matched by name) on example-robot-data's Talos (full), HyQ and
Solo12: idm = rnea, inertia = crba, ddm (both methods) = aba, h = nonLinearEffects, integrate =
pin.integrate, centroidal_momentum = computeCentroidalMomentum, centroidal_map =
computeCentroidalMap; those need `pip install pin
example-robot-data` and are skipped visibly without them unless ROBODYN_REQUIRE names pinocchio
(tests/pinocchio_ref.py). The hand-derived free fall and the refusals need nothing."""

import numpy as np
import pytest

import robodyn

from conftest import robot_path
from pinocchio_ref import SKIP, find, pin

needs_pinocchio = pytest.mark.skipif(SKIP is not None, reason=str(SKIP))

URDFS = ["talos_full_v2.urdf", "hyq_no_sensors.urdf", "solo12.urdf"]


class PinFloating:
    """Pinocchio's free-flyer model with robodyn's order: base entries first (the same
    convention), then the joints matched by name."""

    def __init__(self, path, names):
        m = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        self.model, self.data = m, m.createData()
        assert m.nv == 6 + len(names), (m.nv, len(names))
        joints = [m.joints[m.getJointId(n)] for n in names]
        assert all(j.nq == 1 for j in joints), "no continuous joints in these URDFs"
        self.iv = np.r_[np.arange(6), [j.idx_v for j in joints]]
        self.iq = np.r_[np.arange(7), [j.idx_q for j in joints]]
        assert not np.any(m.armature), "no rotor inertia in these URDFs"

    def q(self, q):
        out = np.zeros(self.model.nq)
        out[self.iq] = q
        return out

    def v(self, x):
        out = np.zeros(self.model.nv)
        out[self.iv] = x
        return out


def random_states(rng, robot, rows):
    q = rng.uniform(-1, 1, (rows, robot.nq))
    quat = rng.normal(size=(rows, 4))
    q[:, 3:7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    v, a = (rng.uniform(-1, 1, (rows, robot.nv)) for _ in range(2))
    return q, v, a


def close(ours, ref, rel=1e-10):
    np.testing.assert_allclose(ours, ref, rtol=0, atol=rel * max(1.0, np.abs(ref).max()))


@needs_pinocchio
@pytest.mark.filterwarnings("ignore::robodyn.RobotFileWarning")
@pytest.mark.parametrize("name", URDFS)
def test_models_match_pinocchio_free_flyer(name):
    path = find(name)
    robot = robodyn.load(path, floating=True)
    assert robot.is_floating and robot.base_kind == "floating"
    assert (robot.nq, robot.nv) == (7 + robot.dof, 6 + robot.dof)
    p = PinFloating(path, robot.joint_names)
    m, d = p.model, p.data
    rng = np.random.default_rng(27)
    qs, vs, accs = random_states(rng, robot, 4)
    # batches (2-D arrays over the cores) against Pinocchio row by row
    taus = robot.idm(qs, vs, accs, friction=False)
    inertias = robot.inertia(qs)
    hs = robot.h(qs, vs, friction=False)
    assert taus.shape == (4, robot.nv) and inertias.shape == (4, robot.nv, robot.nv)
    for r in range(len(qs)):
        pq, pv, pa = p.q(qs[r]), p.v(vs[r]), p.v(accs[r])
        tau_pin = pin.rnea(m, d, pq, pv, pa)[p.iv]
        assert np.abs(tau_pin[:6]).max() > 1e-2  # the base wrench is not trivially zero
        close(taus[r], tau_pin)
        close(robot.idm(qs[r], vs[r], accs[r], friction=False), tau_pin)
        a_pin = pin.crba(m, d, pq)
        a_pin = (np.triu(a_pin) + np.triu(a_pin, 1).T)[np.ix_(p.iv, p.iv)]
        close(inertias[r], a_pin)
        close(hs[r], pin.nonLinearEffects(m, d, pq, pv)[p.iv])
        tau = rng.uniform(-5, 5, robot.nv)
        qdd_pin = pin.aba(m, d, pq, pv, p.v(tau))[p.iv]
        for method in ["composite", "aba"]:
            close(robot.ddm(qs[r], vs[r], tau, method=method, friction=False), qdd_pin, 1e-9)


@needs_pinocchio
@pytest.mark.filterwarnings("ignore::robodyn.RobotFileWarning")
@pytest.mark.parametrize("name", URDFS)
def test_integrate_and_centroidal_quantities_match_pinocchio(name):
    path = find(name)
    robot = robodyn.load(path, floating=True)
    p = PinFloating(path, robot.joint_names)
    m, d = p.model, p.data
    rng = np.random.default_rng(28)
    qs, vs, _ = random_states(rng, robot, 3)
    nexts = robot.integrate(qs, vs, 0.3)
    cm = robot.centroidal_momentum(qs, vs)
    maps = robot.centroidal_map(qs)
    assert maps.shape == (3, 6, robot.nv)
    assert cm["com"].shape == (3, 3) and cm["mass"].shape == (3,)
    for r in range(len(qs)):
        pq, pv = p.q(qs[r]), p.v(vs[r])
        ref = pin.integrate(m, pq, pv * 0.3)[p.iq]
        close(nexts[r], ref)
        close(robot.integrate(qs[r], vs[r], 0.3), ref)
        hg = pin.computeCentroidalMomentum(m, d, pq, pv)
        one = robot.centroidal_momentum(qs[r], vs[r])
        assert isinstance(one["mass"], float)
        close(one["mass"], d.mass[0])
        close(one["com"], d.com[0])
        close(one["linear"], hg.linear)
        close(one["angular"], hg.angular)
        close(cm["angular"][r], hg.angular)
        ag = pin.computeCentroidalMap(m, d, pq)[:, p.iv]
        close(maps[r], ag)
        close(robot.centroidal_map(qs[r]), ag)
        close(maps[r] @ vs[r], np.r_[one["linear"], one["angular"]])


@needs_pinocchio
def test_joint_friction_adds_on_the_joints_only():
    """Talos's URDF has <dynamics damping friction>: robodyn's friction=True adds Fv v + Fs
    sign(v) on the joint rows, none on the base's six."""
    path = find("talos_full_v2.urdf")
    robot = robodyn.load(path, floating=True)
    p = PinFloating(path, robot.joint_names)
    rng = np.random.default_rng(29)
    q, v, a = (x[0] for x in random_states(rng, robot, 1))
    diff = robot.idm(q, v, a) - robot.idm(q, v, a, friction=False)
    drive = (p.model.damping * p.v(v) + p.model.friction * np.sign(p.v(v)))[p.iv]
    assert np.abs(drive).max() > 0.1
    close(diff, drive)


def rx90float():
    return robodyn.load(robot_path("rx90float.toml"), G3=-9.81)


def test_free_fall_by_hand():
    """At rest under no force every body falls with g: ddm gives the base acceleration
    R' g (in the base frame) and zero joint accelerations, and idm of that acceleration
    is zero (no wrench, no torque). Hand-derived, no reference library."""
    robot = rx90float()
    q = np.zeros(robot.nq)
    q[3:7] = np.array([0.3, -0.2, 0.5, 0.7]) / np.linalg.norm([0.3, -0.2, 0.5, 0.7])
    q[7:] = [0.3, -0.4, 0.5, 0.2, -0.1, 0.6]
    x, y, z, w = q[3:7]
    rot = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    expected = np.zeros(robot.nv)
    expected[:3] = rot.T @ np.array([0.0, 0.0, -9.81])
    for method in ["composite", "aba"]:
        np.testing.assert_allclose(robot.ddm(q, method=method), expected, atol=1e-12)
    np.testing.assert_allclose(robot.idm(q, None, expected), np.zeros(robot.nv), atol=1e-10)
    # held at rest, the base needs the whole robot's weight: 20 kg base + 33 kg arm (the file)
    assert abs(np.linalg.norm(robot.idm(q)[:3]) - 9.81 * 53.0) < 1e-9


def test_state_sizes_and_names():
    robot = rx90float()
    assert (robot.nq, robot.nv, robot.dof) == (13, 12, 6)
    assert robot.configuration_names[:7] == ["base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw"]
    assert robot.velocity_names[:6] == ["base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz"]
    assert "floating" in repr(robot)
    q = np.zeros(13)
    q[6] = 1.0
    with pytest.raises(robodyn.DimensionError, match="nq = 7 \\+ 6"):
        robot.idm(np.zeros(6))
    with pytest.raises(robodyn.DimensionError):
        robot.idm(q, np.zeros(13))
    with pytest.raises(robodyn.InputError, match="quaternion"):
        robot.idm(np.zeros(13))
    fixed = robodyn.load(robot_path("rx90.toml"))
    assert (fixed.nq, fixed.nv, fixed.is_floating, fixed.base_kind) == (6, 6, False, "fixed")
    # integrate on a fixed base is q + v dt
    np.testing.assert_allclose(fixed.integrate(np.ones(6), np.arange(6.0), 0.5), 1 + 0.5 * np.arange(6.0))
    with pytest.raises(robodyn.InputError, match="floating base"):
        fixed.centroidal_momentum(np.zeros(6))
    with pytest.raises(robodyn.InputError, match="centroidal map"):
        fixed.centroidal_map(np.zeros(6))


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda r, q: r.jacobian(q, "6"), "Robot.jacobian"),
        (lambda r, q: r.placement(q, "6"), "Robot.placement"),
        (lambda r, q: r.com(q), "Robot.com"),
        (lambda r, q: r.forward_kinematics(q), "Robot.forward_kinematics"),
        (lambda r, q: r.regressor(q), "Robot.regressor"),
        (lambda r, q: r.idm_derivatives(q), "Robot.idm_derivatives"),
        (lambda r, q: r.ddm_derivatives(q), "Robot.ddm_derivatives"),
        (lambda r, q: r.simulate(0.1), "Robot.simulate"),
    ],
)
def test_functions_without_floating_support_say_so(call, name):
    robot = rx90float()
    q = np.zeros(robot.nq)
    q[6] = 1.0
    with pytest.raises(robodyn.InputError, match=name.replace(".", "\\.") + ": robot .* floating base"):
        call(robot, q)


def test_load_floating_refuses_a_fixed_toml():
    with pytest.raises(robodyn.InputError, match="floating base is asked for"):
        robodyn.load(robot_path("rx90.toml"), floating=True)


def random_floating_state(robot, rng):
    q = rng.uniform(-2.0, 2.0, robot.nq)
    quat = rng.normal(size=4)
    q[3:7] = quat / np.linalg.norm(quat)
    return q, rng.uniform(-2.0, 2.0, robot.nv), rng.uniform(-5.0, 5.0, robot.nv)


def test_generated_floating_idm_equals_idm():
    """Robot.generate on a floating robot: the customized inverse dynamic model with the base
    as the root, q (nq), qd, qdd (nv) in, the base wrench then the joint torques out; the
    generated Python against the library's idm (numeric and with the parameters by name). The
    other models refuse a floating robot, naming the one generated."""
    robot = rx90float()
    rng = np.random.default_rng(27)
    g = robot.generate(model="idm", lang="python", numeric=True, name="gen_fidm")
    assert g.multiplications > 0 and g.parameters == []
    ns = {}
    exec(compile(g.code, "<generated>", "exec"), ns)
    s = robot.generate(model="idm", lang="python", name="gen_fsym")
    assert ("M0", 20.0) in s.parameters  # link 0, the base body
    exec(compile(s.code, "<generated>", "exec"), ns)
    for _ in range(5):
        q, v, a = random_floating_state(robot, rng)
        want = robot.idm(q, v, a)
        assert want.shape == (robot.nv,)
        for out in (ns["gen_fidm"](q, v, a), ns["gen_fsym"](q, v, a, dict(s.parameters))):
            out = np.asarray(out, dtype=float).reshape(-1)
            np.testing.assert_allclose(out, want, rtol=0, atol=1e-10 * max(1.0, np.abs(want).max()))
    for model in ["inertia", "h", "ddm", "idm_derivatives"]:
        with pytest.raises(robodyn.InputError, match="floating base"):
            robot.generate(model=model)
