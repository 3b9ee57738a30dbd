"""Floating-base robots from Python (issue 27): `robodyn.load(urdf, floating=True)` and the model
functions on nq / nv vectors.

Cross-checks against Pinocchio with a free-flyer root (`buildModelFromUrdf(path,
JointModelFreeFlyer())`, the joints matched by name) on example-robot-data's Talos (full), HyQ and
Solo12: idm = rnea, inertia = crba, ddm (both methods) = aba, h = nonLinearEffects, integrate =
pin.integrate, centroidal_momentum = computeCentroidalMomentum, centroidal_map =
computeCentroidalMap, and the kinematics (placement and forward_kinematics = oMf of
framesForwardKinematics, jacobian = getFrameJacobian, frame_velocity, frame_acceleration =
getFrameVelocity, getFrameClassicalAcceleration in the three references, com, com_jacobian =
centerOfMass, jacobianCenterOfMass; frames matched by name); those need `pip install pin
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
        (lambda r, q: r.idm_derivatives(q), "Robot.idm_derivatives"),
        (lambda r, q: r.ddm_derivatives(q), "Robot.ddm_derivatives"),
    ],
)
def test_functions_without_floating_support_say_so(call, name):
    robot = rx90float()
    q = np.zeros(robot.nq)
    q[6] = 1.0
    with pytest.raises(robodyn.InputError, match=name.replace(".", "\\.") + ": robot .* floating base"):
        call(robot, q)


def test_ik_refuses_a_floating_robot_with_the_reason():
    robot = rx90float()
    target = np.eye(4)
    q0 = np.zeros(robot.nq)
    q0[6] = 1.0
    for call in (lambda: robot.ik("6", target), lambda: robot.ik("6", target, q0)):
        with pytest.raises(robodyn.InputError, match="Robot.ik: .*floating base, whose pose no joint sets"):
            call()


REFERENCES = ["world", "local", "local_world_aligned"]


@needs_pinocchio
@pytest.mark.filterwarnings("ignore::robodyn.RobotFileWarning")
@pytest.mark.parametrize("name", URDFS)
def test_kinematics_match_pinocchio_free_flyer(name):
    path = find(name)
    robot = robodyn.load(path, floating=True)
    p = PinFloating(path, robot.joint_names)
    m, d = p.model, p.data
    rng = np.random.default_rng(2707)
    rows = 12
    qs, vs, accs = random_states(rng, robot, rows)
    links = [f.name for f in m.frames if f.type == pin.FrameType.BODY]
    frames = [links[k] for k in rng.choice(len(links), 4, replace=False)] + [links[0]]
    nf = len(robot.description_frame_names)
    fk = robot.forward_kinematics(qs)
    assert fk.shape == (rows, nf, 4, 4)
    coms, jcoms = robot.com(qs), robot.com_jacobian(qs)
    assert coms.shape == (rows, 3) and jcoms.shape == (rows, 3, robot.nv)
    by_frame = {}
    for f in frames:
        by_frame[f] = {
            "placement": robot.placement(qs, f),
            "J": {rf: robot.jacobian(qs, f, rf) for rf in REFERENCES},
            "vel": {rf: robot.frame_velocity(qs, vs, f, rf) for rf in REFERENCES},
            "acc": {rf: robot.frame_acceleration(qs, vs, accs, f, rf) for rf in REFERENCES},
        }
    assert by_frame[frames[0]]["J"]["local"].shape == (rows, 6, robot.nv)
    compared = 0
    for r in range(rows):
        pq, pv, pa = p.q(qs[r]), p.v(vs[r]), p.v(accs[r])
        pin.forwardKinematics(m, d, pq, pv, pa)
        pin.computeJointJacobians(m, d, pq)
        pin.updateFramePlacements(m, d)
        for f, ours in by_frame.items():
            fid = m.getFrameId(f, pin.FrameType.BODY)
            close(ours["placement"][r], d.oMf[fid].homogeneous)
            for rf in REFERENCES:
                ref = getattr(pin.ReferenceFrame, rf.upper())
                close(ours["J"][rf][r], pin.getFrameJacobian(m, d, fid, ref)[:, p.iv])
                close(ours["vel"][rf][r], pin.getFrameVelocity(m, d, fid, ref).vector)
                close(ours["acc"][rf][r], pin.getFrameClassicalAcceleration(m, d, fid, ref).vector)
        # every description frame Pinocchio also names (URDF joints, fixed ones included): the
        # origins (the description frame's z is the joint axis, not the URDF joint frame's)
        for j, fname in enumerate(robot.description_frame_names):
            if m.existFrame(fname):
                close(fk[r, j, :3, 3], d.oMf[m.getFrameId(fname)].translation)
                compared += 1
        close(coms[r], pin.centerOfMass(m, d, pq))
        close(jcoms[r], pin.jacobianCenterOfMass(m, d, pq)[:, p.iv])
    assert compared >= rows * robot.dof
    # one state (1-D arrays) gives the same as its row of the batch
    f = frames[0]
    close(robot.jacobian(qs[3], f, "local"), by_frame[f]["J"]["local"][3], rel=0)
    close(robot.com(qs[3]), coms[3], rel=0)
    with pytest.raises(robodyn.DimensionError):
        robot.jacobian(qs[0, 7:], f)


def test_load_floating_refuses_a_fixed_toml():
    with pytest.raises(robodyn.InputError, match="floating base is asked for"):
        robodyn.load(robot_path("rx90.toml"), floating=True)


def quaternion_matrix(q):
    """wR_0 from a quaternion (x, y, z, w), written out (not robodyn's, not Pinocchio's)."""
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def spinning_start(robot, rng):
    q0 = np.zeros(robot.nq)
    q0[7:] = rng.uniform(-1, 1, robot.dof)
    quat = rng.normal(size=4)
    q0[3:7] = quat / np.linalg.norm(quat)
    qd0 = rng.uniform(-1, 1, robot.nv)
    qd0[3:6] = [2.0, -3.0, 4.0]  # a fast spin of the base
    return q0, qd0


def test_simulate_floating_conserves_the_free_body_laws():
    """A free floating RX-90 (gravity given) spinning with its joints driven: the laws of a
    free body, which the simulator does not use, hold on its output. The momenta are those
    of the robot's own centroidal_momentum (checked against Pinocchio above) at the output
    states: P(t) = P(0) + M g t, the angular momentum about the centre of mass constant, the
    energy constant when no torque acts."""
    robot = rx90float()
    g = np.array([0.0, 0.0, -9.81])
    rng = np.random.default_rng(2027)
    q0, qd0 = spinning_start(robot, rng)
    out = robot.simulate(0.5, q0=q0, qd0=qd0, rtol=1e-11, atol=1e-12, output_dt=0.05)
    assert out["q"].shape == (11, robot.nq) and out["qd"].shape == (11, robot.nv)
    assert out["tau"].shape == (11, robot.nv) and not np.any(out["tau"])
    assert out["joint_labels"] == ["1", "2", "3", "4", "5", "6"]
    assert out["q_columns"][:7] == ["base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw"]
    assert out["v_columns"][6] == "qd1"
    np.testing.assert_allclose(np.linalg.norm(out["q"][:, 3:7], axis=1), 1.0, atol=1e-13)
    momenta = [robot.centroidal_momentum(q, v) for q, v in zip(out["q"], out["qd"])]
    mass = momenta[0]["mass"]
    p0, l0 = momenta[0]["linear"], momenta[0]["angular"]
    for t, m in zip(out["t"], momenta):
        np.testing.assert_allclose(m["linear"], p0 + mass * g * t, rtol=0, atol=1e-7 * (1 + abs(p0).max()))
        np.testing.assert_allclose(m["angular"], l0, rtol=0, atol=1e-7 * (1 + abs(l0).max()))
    e = out["energy"]
    assert abs(e - e[0]).max() < 1e-7 * abs(e).max()
    # the joints moved and the base turned: the test is not of a body at rest
    assert abs(out["q"][-1, 7:] - q0[7:]).max() > 0.05
    assert abs(out["q"][-1, 3:7] - q0[3:7]).max() > 0.2


def test_simulate_floating_torque_shapes_and_an_applied_base_force():
    """Joint torques alone leave the base free: a constant (n,), its (nv,) form with a zero
    wrench and a callable give one trajectory. A callable's wrench on the base: a force of
    constant world direction (turned into the base frame from the quaternion of q, written
    out here) gives P(t) = P(0) + F t without gravity."""
    robot = robodyn.load(robot_path("rx90float.toml"), G3=0.0)
    rng = np.random.default_rng(7)
    q0, qd0 = spinning_start(robot, rng)
    tau = rng.uniform(-5, 5, robot.dof)
    kw = dict(q0=q0, qd0=qd0, dt=1e-3, output_dt=0.02)
    joints = robot.simulate(0.2, torque=tau, **kw)
    full = robot.simulate(0.2, torque=np.r_[np.zeros(6), tau], **kw)
    called = robot.simulate(0.2, torque=lambda t, q, qd: tau, **kw)
    for other in (full, called):
        np.testing.assert_array_equal(other["q"], joints["q"])
    np.testing.assert_array_equal(joints["tau"][:, :6], 0.0)

    force = np.array([30.0, -20.0, 10.0])

    def pushed(t, q, qd):
        assert q.shape == (robot.nq,) and qd.shape == (robot.nv,)
        r = quaternion_matrix(q[3:7])
        # the force through the base's origin, its moment zero about O_0
        return np.r_[r.T @ force, np.zeros(3), tau]

    out = robot.simulate(0.3, torque=pushed, q0=q0, qd0=qd0, rtol=1e-11, atol=1e-12, output_dt=0.05)
    p0 = robot.centroidal_momentum(q0, qd0)["linear"]
    for t, q, v in zip(out["t"], out["q"], out["qd"]):
        p = robot.centroidal_momentum(q, v)["linear"]
        np.testing.assert_allclose(p, p0 + force * t, rtol=0, atol=1e-7 * (1 + abs(p0).max()))
    with pytest.raises(robodyn.DimensionError, match="6 joints or 12 with the base wrench"):
        robot.simulate(0.1, torque=np.zeros(7))
    with pytest.raises(robodyn.DimensionError, match="callback returned 3 values"):
        robot.simulate(0.1, torque=lambda t, q, qd: np.zeros(3))


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


def test_floating_regressor_and_base_parameters():
    """The regressor of a floating robot (nv rows: the base wrench then the joints; link 0's ten
    columns after the links') times the standard parameters is the inverse model, a different
    recursion; the base parameters by both methods agree, link 0's ten are all in the base set,
    and the base columns times their values give the same torques."""
    robot = rx90float()
    rng = np.random.default_rng(31)
    k = np.asarray(robot.standard_parameters)
    names = robot.parameter_names
    assert len(k) == 13 * robot.dof + 10 and names[-10:] == ["XX0", "XY0", "XZ0", "YY0", "YZ0", "ZZ0", "MX0", "MY0", "MZ0", "M0"]
    sym = robot.base_parameters(method="symbolic")
    num = robot.base_parameters(method="numeric")
    assert len(sym) == len(num) == 70 and sorted(sym.indices) == sorted(num.indices)
    assert set(range(13 * robot.dof, 13 * robot.dof + 10)) <= set(sym.indices)
    beta = np.array(sym.values, dtype=float)
    for _ in range(5):
        q = rng.uniform(-1, 1, robot.nq)
        q[3:7] /= np.linalg.norm(q[3:7])
        v, a = rng.uniform(-1, 1, robot.nv), rng.uniform(-1, 1, robot.nv)
        tau = robot.idm(q, v, a)
        phi = robot.regressor(q, v, a)
        assert phi.shape == (robot.nv, len(k))
        close(phi @ k, tau)
        # the base columns are the base parameters' in their listed order, for both methods
        # (the numerical method selects link 0 first but lists it in K order, after the links)
        base_phi = robot.regressor(q, v, a, columns="base")
        close(base_phi @ np.array(num.values, dtype=float), tau)
        close(base_phi @ beta, tau)
    assert robot.regressor_columns(columns="base") == num.names == sym.names
