"""Tree models on the bundled robots: every function, one state and N states, cross-checked
against each other (idm = A qdd + H, ddm inverts idm by both methods, regressor times
parameters = idm, generated code = idm, batch rows = single states)."""

import numpy as np
import pytest

import robodyn
from conftest import CLOSED, TREES, random_states, robot_path

ROBOTS = TREES + CLOSED  # a closed robot's Robot is its equivalent tree
# the TX40 file's link 6 has no inertia about its axis and no rotor inertia (IA = 0, to be
# identified): A is singular at joint 6 and the direct model must refuse
SINGULAR_A = {"tx40.toml"}


@pytest.mark.parametrize("name", ROBOTS)
def test_idm_inertia_h_ddm_agree(name, rng):
    robot = robodyn.load(robot_path(name))
    n = robot.nq
    q, qd, qdd = random_states(rng, n)
    tau = robot.idm(q, qd, qdd)
    a = robot.inertia(q)
    h = robot.h(q, qd)
    assert tau.shape == (n,) and a.shape == (n, n) and h.shape == (n,)
    assert np.abs(tau).max() > 1e-3, "torques vanish: the test would be vacuous"
    # Γ = A qdd + H (composite links and Newton–Euler are separate recursions)
    np.testing.assert_allclose(a @ qdd + h, tau, rtol=0, atol=1e-9 * max(1.0, np.abs(tau).max()))
    np.testing.assert_allclose(a, a.T, atol=1e-12)
    for method in ["composite", "aba"]:
        if name in SINGULAR_A:
            with pytest.raises(robodyn.SingularConfiguration, match="joint 6"):
                robot.ddm(q, qd, tau, method=method)
            continue
        back = robot.ddm(q, qd, tau, method=method)
        np.testing.assert_allclose(back, qdd, atol=1e-8)


@pytest.mark.parametrize("name", ROBOTS)
def test_batches_equal_single_states(name, rng):
    robot = robodyn.load(robot_path(name))
    n = robot.nq
    q, qd, qdd = random_states(rng, n, rows=37)
    tau = robot.idm(q, qd, qdd)
    a = robot.inertia(q)
    h = robot.h(q, qd)
    if name in SINGULAR_A:
        with pytest.raises(robodyn.SingularConfiguration) as e:
            robot.ddm(q, qd, tau, method="aba")
        assert e.value.row == 1
        return
    qdd_back = robot.ddm(q, qd, tau, method="aba")
    fk = robot.forward_kinematics(q)
    assert tau.shape == (37, n) and a.shape == (37, n, n) and fk.shape == (37, robot.nf, 4, 4)
    for r in [0, 17, 36]:
        np.testing.assert_array_equal(tau[r], robot.idm(q[r], qd[r], qdd[r]))
        np.testing.assert_array_equal(a[r], robot.inertia(q[r]))
        np.testing.assert_array_equal(h[r], robot.h(q[r], qd[r]))
        np.testing.assert_array_equal(qdd_back[r], robot.ddm(q[r], qd[r], tau[r], method="aba"))
        np.testing.assert_array_equal(fk[r], robot.forward_kinematics(q[r]))
    np.testing.assert_allclose(qdd_back, qdd, atol=1e-8)


def test_defaults_and_array_likes():
    robot = robodyn.load(robot_path("rx90.toml"))
    q = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    np.testing.assert_array_equal(robot.idm(q), robot.idm(np.array(q), np.zeros(6), np.zeros(6)))
    np.testing.assert_array_equal(robot.idm(q), robot.h(q))  # H(q, 0) = Γ(q, 0, 0)
    # non-contiguous and integer inputs are converted
    big = np.zeros((6, 2))
    big[:, 0] = q
    np.testing.assert_array_equal(robot.idm(big[:, 0]), robot.idm(q))
    np.testing.assert_array_equal(robot.idm([0, 0, 0, 0, 0, 0]), robot.idm(np.zeros(6)))
    # empty batch
    assert robot.idm(np.zeros((0, 6))).shape == (0, 6)


@pytest.mark.parametrize("name", ["rx90.toml", "torso2arms.toml", "scara.toml"])
def test_forward_kinematics_is_a_chain_of_rigid_transforms(name, rng):
    robot = robodyn.load(robot_path(name))
    q = rng.uniform(-1, 1, robot.nq)
    t = robot.forward_kinematics(q)
    ants = robot.antecedents
    for j in range(robot.nf):
        r = t[j, :3, :3]
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
        np.testing.assert_array_equal(t[j, 3], [0, 0, 0, 1])
    # moving joint k moves exactly the frames of its subtree
    k = 0
    q2 = q.copy()
    q2[k] += 0.3
    t2 = robot.forward_kinematics(q2)
    frame = robot.joint_frames[k]

    def below(j):  # frame j (1-based) is frame `frame` or a descendant
        while j != 0:
            if j == frame:
                return True
            j = ants[j - 1]
        return False

    for j in range(1, robot.nf + 1):
        moved = not np.allclose(t[j - 1], t2[j - 1], atol=1e-12)
        if not below(j):
            assert not moved, f"frame {j} moved"
    # the joint axis z_j of a revolute joint keeps its direction while it turns
    np.testing.assert_allclose(t[frame - 1][:3, 2], t2[frame - 1][:3, 2], atol=1e-12)


def test_idm_is_the_derivative_of_energy_along_a_simulation():
    """Simulation without friction and torque conserves energy (integrator and the direct model
    against the energy of the same robot); a torque callback equals the same constant torque."""
    robot = robodyn.load(robot_path("rx90.toml"))
    zero = {p: 0.0 for p in robot.parameter_names if p.startswith(("FS", "FV"))}
    frictionless = robot.with_values(**{k: v for k, v in zero.items() if k in robot.symbols})
    n = robot.nq
    q0 = np.linspace(0.1, 0.6, n)
    traj = frictionless.simulate(0.5, q0=q0, output_dt=0.05)
    assert traj["q"].shape == (11, n) and traj["t"].shape == (11,)
    if all(abs(v) == 0 for k, v in frictionless.symbols.items() if k.startswith(("FS", "FV"))):
        drift = np.abs(traj["energy"] - traj["energy"][0]).max()
        assert drift < 1e-6 * max(1.0, abs(traj["energy"][0]))
    tau = np.linspace(1.0, -1.0, n)
    a = robot.simulate(0.2, q0=q0, torque=tau, dt=1e-3, output_dt=0.05)
    b = robot.simulate(0.2, q0=q0, torque=lambda t, q, qd: tau, dt=1e-3, output_dt=0.05)
    np.testing.assert_allclose(a["q"], b["q"], atol=1e-12)
    np.testing.assert_allclose(b["tau"], np.tile(tau, (5, 1)), atol=0)
    # qdd of each row is the direct model at that row
    np.testing.assert_allclose(a["qdd"][2], robot.ddm(a["q"][2], a["qd"][2], tau), atol=1e-9)
    series = robot.simulate(0.2, q0=q0, torque=([0.0, 1.0], [tau, tau]), dt=1e-3, output_dt=0.05)
    np.testing.assert_allclose(series["q"], a["q"], atol=1e-12)


@pytest.mark.parametrize("name", ["rx90.toml", "scara.toml", "torso2arms.toml", "tx40.toml"])
def test_regressor_times_parameters_is_idm(name, rng):
    robot = robodyn.load(robot_path(name))
    n = robot.nq
    q, qd, qdd = random_states(rng, n, rows=5)
    tau = robot.idm(q, qd, qdd).reshape(-1)
    phi = robot.regressor(q, qd, qdd)
    names = robot.regressor_columns()
    assert phi.shape == (5 * n, len(names))
    k = dict(zip(robot.parameter_names, robot.standard_parameters))
    np.testing.assert_allclose(phi @ np.array([k[c] for c in names]), tau, atol=1e-9 * np.abs(tau).max())
    # base columns with the base parameters' values (numeric method, independent of the
    # symbolic rules that choose the base columns)
    bp = robot.base_parameters(method="both")
    phib = robot.regressor(q, qd, qdd, columns="base")
    assert robot.regressor_columns(columns="base") == bp.names
    np.testing.assert_allclose(phib @ np.array(bp.values), tau, atol=1e-8 * np.abs(tau).max())
    # single state = first rows of the stack
    np.testing.assert_array_equal(robot.regressor(q[0], qd[0], qdd[0]), phi[:n])


@pytest.mark.parametrize("name", ["rx90.toml", "rx90.par", "scara.toml", "sr400.toml", "torso2arms.toml"])
def test_base_parameters_numeric_agrees_with_symbolic(name):
    robot = robodyn.load(robot_path(name))
    s = robot.base_parameters(method="symbolic")
    nb = robot.base_parameters(method="numeric")
    assert len(s) == len(nb) > 0
    assert set(s.no_effect) == set(nb.no_effect)
    assert len(s.equations) == len(s.names) == len(s.values)
    # the coefficient tables reproduce the values from the standard parameters
    k = dict(zip(robot.parameter_names, robot.standard_parameters))
    for b in [s, nb]:
        kc = np.array([k[c] for c in b.columns])
        np.testing.assert_allclose(b.coefficients @ kc, np.array(b.values, dtype=float), atol=1e-9)
    assert "grouped" in s.report.lower() or s.grouped == []


def test_sr400_base_parameters_table_10_2():
    robot = robodyn.load(robot_path("sr400.toml"))
    bp = robot.base_parameters(method="symbolic", friction=False)
    assert len(bp) == 42  # Table 10.2


@pytest.mark.parametrize("name", ["rx90.toml", "scara.toml"])
def test_generated_python_code_equals_idm(name, rng):
    robot = robodyn.load(robot_path(name))
    g = robot.generate(model="idm", lang="python", numeric=True, name="gen_idm")
    assert g.multiplications > 0 and g.additions > 0
    ns = {}
    exec(compile(g.code, "<generated>", "exec"), ns)
    q, qd, qdd = random_states(rng, robot.nq)
    # the generated code takes tree vectors over frames 1..NL (movable joints here)
    out = np.asarray(ns["gen_idm"](q, qd, qdd), dtype=float).reshape(-1)
    np.testing.assert_allclose(out, robot.idm(q, qd, qdd), atol=1e-9)
    assert g.parameters == []  # numeric: the values are in the code, no p
    # symbolic: the parameters by name, their values from Generated.parameters
    g = robot.generate(model="idm", lang="python", name="gen_sym")
    names = [n for n, _ in g.parameters]
    ns = {}
    exec(compile(g.code, "<generated>", "exec"), ns)
    assert list(ns["GEN_SYM_PARAMETERS"]) == names
    out = np.asarray(ns["gen_sym"](q, qd, qdd, dict(g.parameters)), dtype=float)
    np.testing.assert_allclose(out.reshape(-1), robot.idm(q, qd, qdd), atol=1e-9)
    text = robot.generate(model="inertia", lang="text")
    assert text.multiplications > 0 and "A" in text.code


def test_generated_idm_derivatives_equal_the_analytical_ones(rng):
    # generated forward-mode code (three N x N column-major blocks) against the library's
    # analytical derivatives (world-frame recursion): two independent routes
    robot = robodyn.load(robot_path("rx90.toml"))
    g = robot.generate(model="idm_derivatives", lang="python", numeric=True, name="gen_d")
    assert g.multiplications > 0 and g.additions > 0
    ns = {}
    exec(compile(g.code, "<generated>", "exec"), ns)
    n = robot.nq
    for _ in range(3):
        q, qd, qdd = random_states(rng, n)
        out = np.asarray(ns["gen_d"](q, qd, qdd), dtype=float).reshape(-1)
        assert out.shape == (3 * n * n,)
        blocks = [out[k * n * n:(k + 1) * n * n].reshape(n, n, order="F") for k in range(3)]
        for generated, analytical in zip(blocks, robot.idm_derivatives(q, qd, qdd)):
            np.testing.assert_allclose(generated, analytical, rtol=1e-9, atol=1e-9)
    with pytest.raises(robodyn.InputError, match="idm_derivatives"):
        robot.generate(model="idm-derivative", lang="python")


def test_properties_set_and_save(tmp_path):
    robot = robodyn.load(robot_path("sr400.toml"))
    assert robot.nq == len(robot.joint_names) == robot.nl  # all tree joints movable
    assert robot.nf == 2 * robot.nj - robot.nl
    assert len(robot.link_names) == robot.nl and len(robot.antecedents) == robot.nf
    assert not robot.is_tree and len(robot.loops) == 1
    assert robot.loops[0]["cut"] == 9
    cuts = {l["cut"] for l in robot.loops}
    assert set(robot.actuated) | set(robot.passive) | cuts == set(range(1, robot.nj + 1))
    sym = robot.symbols
    assert sym, "the SR400 file defines symbols"
    name, value = next(iter(sym.items()))
    other = robot.with_values(**{name: value * 1.5 + 0.1})
    assert other.symbols[name] == value * 1.5 + 0.1 and robot.symbols[name] == value
    path = tmp_path / "sr400_copy.toml"
    other.save(path)
    back = robodyn.load(path)
    assert back.symbols[name] == other.symbols[name]
    q = np.linspace(0.1, 0.9, robot.nq)
    np.testing.assert_allclose(back.idm(q, q, q), other.idm(q, q, q), rtol=1e-12)
    robot.set(**{name: value * 1.5 + 0.1})
    np.testing.assert_array_equal(robot.idm(q, q, q), other.idm(q, q, q))
    same = robodyn.Robot.from_toml_str(other.to_toml())
    np.testing.assert_allclose(same.idm(q, q, q), other.idm(q, q, q), rtol=1e-12)
    urdf = robodyn.load(robot_path("rx90.urdf"))
    assert urdf.nq == len(urdf.joint_names) == 6
