"""Kinematics by frame name (placement, jacobian in three references, frame velocity and
classical acceleration, centre of mass and its Jacobian) against Pinocchio on the UR5 and Panda
URDFs of example-robot-data, to 1e-12 on 50 random configurations; batches equal the rows;
Fortran-ordered input; the errors; the closed-form inverse geometric model (every solution
placed at the target); and a closed chain's J_a against finite differences of its placements.

The Pinocchio checks need `pip install pin example-robot-data`; they skip visibly without them
unless ROBODYN_REQUIRE names them (tests/pinocchio_ref.py)."""

import numpy as np
import pytest

import robodyn
from conftest import robot_path

from pinocchio_ref import SKIP, Pin, find, pin

needs_pinocchio = pytest.mark.skipif(SKIP is not None, reason=SKIP or "")

URDFS = ["ur5_robot.urdf", "panda.urdf"]
REFERENCES = ["world", "local", "local_world_aligned"]
TOL = 1e-12


def pin_ref(name):
    return {"world": pin.WORLD, "local": pin.LOCAL, "local_world_aligned": pin.LOCAL_WORLD_ALIGNED}[name]


def assert_close(ours, theirs, what):
    scale = max(1.0, np.abs(theirs).max())
    err = np.abs(np.asarray(ours) - np.asarray(theirs)).max() / scale
    assert err <= TOL, f"{what}: {err:.2e} > {TOL:.0e}"
    return err


@needs_pinocchio
@pytest.mark.parametrize("name", URDFS)
def test_placements_jacobians_com_match_pinocchio(name):
    path = find(name)
    robot = robodyn.load(path)
    p = Pin(path, robot.joint_names)
    frames = p.body_frames()
    assert len(frames) >= 6
    assert set(frames) <= set(robot.frame_names), set(frames) - set(robot.frame_names)
    rng = np.random.default_rng(11)
    n = robot.nq
    qs = rng.uniform(-np.pi, np.pi, (50, n))
    qds, qdds = rng.uniform(-2, 2, (50, n)), rng.uniform(-2, 2, (50, n))
    worst = 0.0
    for q, qd, qdd in zip(qs, qds, qdds):
        pq, pv, pa = p.q(q), p.v(qd), p.v(qdd)
        pin.forwardKinematics(p.model, p.data, pq, pv, pa)
        pin.updateFramePlacements(p.model, p.data)
        pin.computeJointJacobians(p.model, p.data, pq)
        for f in frames:
            fid = p.model.getFrameId(f)
            worst = max(worst, assert_close(robot.placement(q, f), p.data.oMf[fid].homogeneous, f"{f} placement"))
            for ref in REFERENCES:
                j_pin = pin.getFrameJacobian(p.model, p.data, fid, pin_ref(ref))[:, p.iv]
                worst = max(worst, assert_close(robot.jacobian(q, f, ref), j_pin, f"{f} J {ref}"))
                v_pin = pin.getFrameVelocity(p.model, p.data, fid, pin_ref(ref)).vector
                worst = max(worst, assert_close(robot.frame_velocity(q, qd, f, ref), v_pin, f"{f} v {ref}"))
                a_pin = pin.getFrameClassicalAcceleration(p.model, p.data, fid, pin_ref(ref)).vector
                worst = max(worst, assert_close(robot.frame_acceleration(q, qd, qdd, f, ref), a_pin, f"{f} a {ref}"))
        com_pin = pin.centerOfMass(p.model, p.data, pq)
        worst = max(worst, assert_close(robot.com(q), com_pin, "com"))
        jcom_pin = pin.jacobianCenterOfMass(p.model, p.data, pq)[:, p.iv]
        worst = max(worst, assert_close(robot.com_jacobian(q), jcom_pin, "com_jacobian"))
    # the one computeFrameJacobian call (placements and Jacobian from q alone) on the last q
    fid = p.model.getFrameId(frames[-1])
    for ref in REFERENCES:
        j = pin.computeFrameJacobian(p.model, p.data, p.q(qs[-1]), fid, pin_ref(ref))[:, p.iv]
        assert_close(robot.jacobian(qs[-1], frames[-1], ref), j, "computeFrameJacobian")
    assert np.abs(robot.mass - pin.computeTotalMass(p.model)) <= TOL * robot.mass
    print(f"{name}: worst relative difference to Pinocchio {worst:.2e} over {len(frames)} frames")


@needs_pinocchio
def test_batches_equal_rows_and_fortran_input():
    robot = robodyn.load(find("panda.urdf"))
    frame = robot.frame_names[-1]
    rng = np.random.default_rng(3)
    n = robot.nq
    qs, qds, qdds = (rng.uniform(-1, 1, (7, n)) for _ in range(3))
    calls = {
        "placement": (lambda q, qd, qdd: robot.placement(q, frame), (4, 4)),
        "jacobian": (lambda q, qd, qdd: robot.jacobian(q, frame, "local"), (6, n)),
        "frame_velocity": (lambda q, qd, qdd: robot.frame_velocity(q, qd, frame, "local_world_aligned"), (6,)),
        "frame_acceleration": (lambda q, qd, qdd: robot.frame_acceleration(q, qd, qdd, frame), (6,)),
        "com": (lambda q, qd, qdd: robot.com(q), (3,)),
        "com_jacobian": (lambda q, qd, qdd: robot.com_jacobian(q), (3, n)),
    }
    for name, (f, shape) in calls.items():
        batch = f(qs, qds, qdds)
        assert batch.shape == (7,) + shape, name
        for r in range(7):
            np.testing.assert_array_equal(batch[r], f(qs[r], qds[r], qdds[r]), err_msg=name)
        fortran = f(np.asfortranarray(qs), np.asfortranarray(qds), np.asfortranarray(qdds))
        np.testing.assert_array_equal(fortran, batch, err_msg=name)
        # a strided row (every other entry of a longer row) is read by logical index too
        wide = np.zeros((2 * n,))
        wide[::2] = qs[0]
        np.testing.assert_array_equal(f(wide[::2], qds[0], qdds[0]), batch[0], err_msg=name)
    out = np.empty((7, 6, n))
    assert robot.jacobian(qs, frame, out=out) is out
    np.testing.assert_array_equal(out, robot.jacobian(qs, frame))


def test_errors_name_the_frame_the_reference_and_the_input():
    robot = robodyn.load(robot_path("rx90.urdf"))
    q = np.zeros(robot.nq)
    with pytest.raises(robodyn.InputError, match="elbw") as e:
        robot.placement(q, "elbw")
    assert "elbow" in str(e.value)  # the near names
    with pytest.raises(robodyn.InputError, match="nowhere"):
        robot.jacobian(q, "nowhere")
    with pytest.raises(ValueError, match='"world", "local" or "local_world_aligned"'):
        robot.jacobian(q, "elbow", "global")
    with pytest.raises(ValueError, match="local_world_aligned"):
        robot.frame_velocity(q, q, "elbow", "LOCAL")
    with pytest.raises(robodyn.DimensionError, match=r"\(5,\)"):
        robot.placement(np.zeros(5), "elbow")
    with pytest.raises(robodyn.DimensionError):
        robot.com_jacobian(np.zeros((3, 7)))
    with pytest.raises(robodyn.DimensionError):
        robot.frame_velocity(q, np.zeros(4), "elbow")
    bad = q.copy()
    bad[2] = np.nan
    for call in [lambda: robot.placement(bad, "elbow"), lambda: robot.jacobian(bad, "elbow"),
                 lambda: robot.com(bad), lambda: robot.com_jacobian(bad),
                 lambda: robot.frame_velocity(q, bad, "elbow"),
                 lambda: robot.frame_acceleration(q, q, bad, "elbow")]:
        with pytest.raises(robodyn.NotFiniteError):
            call()
    rows = np.zeros((4, robot.nq))
    rows[2, 1] = np.inf
    with pytest.raises(robodyn.NotFiniteError) as e:
        robot.jacobian(rows, "elbow")
    assert e.value.row == 3


def test_frame_names_are_the_names_placement_accepts():
    robot = robodyn.load(robot_path("rx90.urdf"))
    names = robot.frame_names
    assert len(names) == len(set(names))
    for f in names:
        assert robot.placement(np.zeros(robot.nq), f).shape == (4, 4)
    assert len(robot.description_frame_names) == robot.nf
    fk = robot.forward_kinematics(np.full(robot.nq, 0.3))
    for j, f in enumerate(robot.description_frame_names):
        np.testing.assert_array_equal(robot.placement(np.full(robot.nq, 0.3), str(j + 1)), fk[j], err_msg=f)


def test_ik_solutions_reach_the_target():
    robot = robodyn.load(robot_path("rx90.toml"))
    frame = robot.description_frame_names[-1]
    rng = np.random.default_rng(17)
    n = robot.nq
    solved = 0
    for _ in range(20):
        q = rng.uniform(-2.5, 2.5, n)
        target = robot.placement(q, frame)
        res = robot.ik(frame, target)
        sols = res["q"]
        assert sols.ndim == 2 and sols.shape[1] == n and 1 <= len(sols) <= 8
        assert res["within_limits"].shape == res["singular"].shape == (len(sols),)
        assert res["within_limits"].dtype == bool
        for s in sols:
            np.testing.assert_allclose(robot.placement(s, frame), target, rtol=0, atol=1e-10)
        # the configuration the target came from is one of the solutions (mod 2 pi)
        d = np.angle(np.exp(1j * (sols - q)))
        assert np.abs(d).max(axis=1).min() < 1e-8
        solved += len(sols)
    assert solved >= 20 * 4
    # Fortran-ordered target, and a tool frame (fixed on the last link)
    res = robot.ik(frame, np.asfortranarray(target))
    assert len(res["q"]) >= 1
    far = target.copy()
    far[:3, 3] = [100.0, 0.0, 0.0]
    assert robot.ik(frame, far)["q"].shape == (0, n)
    bad = target.copy()
    bad[0, 0] = np.nan
    with pytest.raises(robodyn.NotFiniteError):
        robot.ik(frame, bad)
    with pytest.raises(robodyn.InputError, match="orthonormal"):
        robot.ik(frame, 2 * np.eye(4) - np.diag([0, 0, 0, 1.0]))
    with pytest.raises(robodyn.DimensionError):
        robot.ik(frame, np.eye(3))
    with pytest.raises(robodyn.InputError, match="nowhere"):
        robot.ik("nowhere", target)


def ik_round_trip(robot, frame, rng, count=10):
    for _ in range(count):
        q = rng.uniform(-2.5, 2.5, robot.nq)
        target = robot.placement(q, frame)
        sols = robot.ik(frame, target)["q"]
        assert len(sols) >= 1, frame
        for s in sols:
            np.testing.assert_allclose(robot.placement(s, frame), target, rtol=0, atol=1e-10)
        assert np.abs(np.angle(np.exp(1j * (sols - q)))).max(axis=1).min() < 1e-8


def test_ik_on_a_urdf_link_frame():
    """A URDF link's body frame (a tool on the last joint's frame) as the IK's frame."""
    robot = robodyn.load(robot_path("rx90.urdf"))
    ik_round_trip(robot, "link6", np.random.default_rng(5))
    with pytest.raises(robodyn.InputError, match="6 needed"):
        robot.ik("link5", robot.placement(np.zeros(6), "link5"))


@needs_pinocchio
def test_ik_on_the_ur5_tool0():
    """The offset-wrist class on example-robot-data's UR5 (tool0: a frame fixed after joint 6)."""
    robot = robodyn.load(find("ur5_robot.urdf"))
    ik_round_trip(robot, "tool0", np.random.default_rng(6))


def test_ik_without_closed_form_raises():
    robot = robodyn.load(robot_path("scara.toml"))
    frame = robot.description_frame_names[-1]
    target = robot.placement(np.zeros(robot.nq), frame)
    with pytest.raises(robodyn.Error, match="closed-form|closed form"):
        robot.ik(frame, target)


def test_numeric_ik_with_q0_places_the_frame():
    """ik(frame, T, q0): the numeric model on a robot without a closed form (the SCARA) and on
    the RX-90, each solution placed at the target by placement (a round trip); a batch of
    targets equals the calls one by one."""
    rng = np.random.default_rng(11)
    for name in ["scara.toml", "rx90.urdf"]:
        robot = robodyn.load(robot_path(name))
        frame = robot.description_frame_names[-1]
        qs = rng.uniform(-1.0, 1.0, (3, robot.nq))
        targets = np.array([robot.placement(q, frame) for q in qs])
        starts = qs + rng.uniform(-0.3, 0.3, qs.shape)
        for t, q0 in zip(targets, starts):
            r = robot.ik(frame, t, q0=q0)
            assert r["converged"], (name, r)
            assert r["q"].shape == (robot.nq,)
            assert r["position_error"] <= 1e-10 and r["rotation_error"] <= 1e-10
            np.testing.assert_allclose(robot.placement(r["q"], frame), t, rtol=0, atol=1e-9)
        batch = robot.ik(frame, targets, q0=starts)
        assert batch["q"].shape == (3, robot.nq) and batch["converged"].all()
        for k in range(3):
            one = robot.ik(frame, targets[k], q0=starts[k])
            np.testing.assert_array_equal(batch["q"][k], one["q"])
        with pytest.raises(robodyn.DimensionError, match="q0"):
            robot.ik(frame, targets[0], q0=np.zeros(robot.nq + 1))
        with pytest.raises(robodyn.DimensionError):
            robot.ik(frame, targets, q0=starts[:2])


def test_closed_chain_jacobian_is_the_derivative_of_the_placement():
    robot = robodyn.load(robot_path("sr400.toml"))
    chain = robodyn.ClosedChain(robot)
    frame = "7"
    q_a = np.array(chain.branch["q_a"]) + 0.05
    j = chain.jacobian(q_a, frame, "local_world_aligned")
    assert j.shape == (6, chain.nq)

    def position(qa):
        return robot.placement(chain.closure(qa)["q_tree"], frame)[:3, 3]

    h = 1e-6
    fd = np.zeros((3, chain.nq))
    for k in range(chain.nq):
        e = np.zeros(chain.nq)
        e[k] = h
        fd[:, k] = (position(q_a + e) - position(q_a - e)) / (2 * h)
    np.testing.assert_allclose(j[:3], fd, rtol=0, atol=1e-7 * max(1.0, np.abs(fd).max()))
    assert np.abs(fd).max() > 1e-2
    rows = np.stack([q_a, q_a + 0.01])
    chain.reset()
    batch = chain.jacobian(rows, frame)
    assert batch.shape == (2, 6, chain.nq)
    with pytest.raises(ValueError):
        chain.jacobian(q_a, frame, "global")


@pytest.mark.parametrize("name, floating", [("rx90.urdf", False), ("scara.toml", False), ("rx90float.toml", True)])
def test_jacobian_time_variation_is_the_derivative_of_the_jacobian(name, floating):
    """jacobian_time_variation(q, qd) = d/dt J(q(t)) at t = 0 along q(t) = q + t qd (a floating
    base: integrate(q, qd, t), its pose on SE(3)), by central differences of `jacobian`
    (h = 1e-5: truncation ~1e-10, rounding ~1e-11); J̇ qd is of the order |qd|^2 ~ 1, so a missing
    term cannot hide under the tolerance."""
    robot = robodyn.load(robot_path(name), **({"G3": -9.81} if floating else {}))
    rng = np.random.default_rng(26)
    q = rng.uniform(-1, 1, robot.nq)
    if floating:
        q[3:7] /= np.linalg.norm(q[3:7])
    qd = rng.uniform(-1, 1, robot.nv)
    h = 1e-5
    at = (lambda t: robot.integrate(q, qd, t)) if floating else (lambda t: q + t * qd)
    for frame in robot.frame_names[1:]:
        for ref in ("world", "local", "local_world_aligned"):
            dj = robot.jacobian_time_variation(q, qd, frame, ref)
            assert dj.shape == (6, robot.nv)
            fd = (robot.jacobian(at(h), frame, ref) - robot.jacobian(at(-h), frame, ref)) / (2 * h)
            np.testing.assert_allclose(dj, fd, rtol=0, atol=1e-7 * max(1.0, np.abs(fd).max()),
                                       err_msg=f"{name} {frame} {ref}")
    batch = robot.jacobian_time_variation(np.array([q, q]), np.array([qd, 2 * qd]), robot.frame_names[-1])
    np.testing.assert_allclose(batch[1], 2 * batch[0], rtol=1e-12, atol=1e-14)
