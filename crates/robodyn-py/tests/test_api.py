"""The Python API as Pinocchio users meet it (issue 30 item 12): `v`/`a` as aliases of
`qd`/`qdd`, `friction=False` giving Pinocchio's rnea/aba on URDFs with <dynamics>, docstrings
with shapes and units on every function, the .pyi stubs in step with the extension, `out=`
checked, and a legged robot's URDF loaded with a fixed base said as a warning."""

import ast
import inspect
import pathlib
import warnings

import numpy as np
import pytest

import robodyn
from conftest import robot_path

STUBS = pathlib.Path(robodyn.__file__).with_name("__init__.pyi")


def test_v_and_a_are_aliases_of_qd_and_qdd():
    robot = robodyn.load(robot_path("rx90.toml"))
    rng = np.random.default_rng(5)
    q, qd, qdd = (rng.uniform(-1, 1, (3, 6)) for _ in range(3))
    ref = robot.idm(q, qd, qdd)
    np.testing.assert_array_equal(robot.idm(q, v=qd, a=qdd), ref)
    np.testing.assert_array_equal(robot.idm(q, qd, a=qdd), ref)
    np.testing.assert_array_equal(robot.h(q, v=qd), robot.h(q, qd))
    tau = robot.idm(q, qd, qdd)
    np.testing.assert_array_equal(robot.ddm(q, v=qd, tau=tau), robot.ddm(q, qd, tau))
    np.testing.assert_array_equal(robot.regressor(q, v=qd, a=qdd), robot.regressor(q, qd, qdd))
    for call in [lambda: robot.idm(q, qd, v=qd), lambda: robot.idm(q, None, qdd, a=qdd),
                 lambda: robot.h(q, qd, v=qd), lambda: robot.ddm(q, qd, tau, v=qd)]:
        with pytest.raises(robodyn.InputError, match="Pinocchio's name"):
            call()
    chain = robodyn.ClosedChain(robodyn.load(robot_path("fourbar.toml")))
    qa = np.array(chain.branch["q_a"])
    a = chain.idm(qa, [0.3], [0.1])
    chain.reset()
    np.testing.assert_array_equal(chain.idm(qa, v=[0.3], a=[0.1]), a)
    with pytest.raises(robodyn.InputError):
        chain.idm(qa, [0.3], v=[0.3])


def erd(name):
    pytest.importorskip("pinocchio")
    cmeel = pytest.importorskip("cmeel")
    root = pathlib.Path(cmeel.__file__).parents[1] / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
    hits = sorted(root.rglob(name))
    if not hits:
        pytest.skip(f"{name} not in example-robot-data")
    return hits[0]


@pytest.mark.parametrize("name", ["talos_left_arm.urdf", "z1.urdf", "panda.urdf"])
def test_friction_false_is_pinocchios_rnea_and_aba(name):
    """URDF <dynamics damping friction> are robodyn's FV, FS; Pinocchio's rnea/aba leave them
    out. friction=False gives Pinocchio's numbers; the default adds damping v + friction sign(v)
    (the recipe of docs/python.md)."""
    import pinocchio as pin

    path = erd(name)
    robot = robodyn.load(path)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    assert model.nq == model.nv == robot.nq
    assert [model.names[i] for i in range(1, model.njoints)] == robot.joint_names
    assert model.damping.any(), "the URDF has <dynamics>: the test would be vacuous"
    rng = np.random.default_rng(11)
    for _ in range(4):
        q, v, a = (rng.uniform(-1, 1, robot.nq) for _ in range(3))
        tau_pin = pin.rnea(model, data, q, v, a)
        scale = max(1.0, np.abs(tau_pin).max())
        np.testing.assert_allclose(robot.idm(q, v=v, a=a, friction=False), tau_pin, rtol=0, atol=1e-10 * scale)
        drive = model.damping * v + model.friction * np.sign(v)
        np.testing.assert_allclose(robot.idm(q, v=v, a=a), tau_pin + drive, rtol=0, atol=1e-10 * scale)
        assert np.abs(drive).max() > 1e-3
        np.testing.assert_allclose(robot.h(q, v=v, friction=False), pin.nonLinearEffects(model, data, q, v), rtol=0, atol=1e-10 * scale)
        tau = rng.uniform(-5, 5, robot.nq)
        acc = pin.aba(model, data, q, v, tau)
        for method in ["aba", "composite"]:
            np.testing.assert_allclose(robot.ddm(q, v=v, tau=tau, method=method, friction=False), acc,
                                       rtol=0, atol=1e-9 * max(1.0, np.abs(acc).max()))


def test_a_legged_urdf_says_its_base_is_fixed():
    path = erd("solo12.urdf")
    with pytest.warns(robodyn.RobotFileWarning, match=r"legged robot.*`base_link` as a fixed base") as w:
        robot = robodyn.load(path)
    assert robot.nq == 12
    assert w[0].filename == __file__  # the warning points at the caller's line
    with warnings.catch_warnings():
        warnings.simplefilter("error", robodyn.RobotFileWarning)
        robodyn.load(erd("ur5_robot.urdf"))  # an arm: no such warning


def stub_functions():
    """(owner, name) -> ast.FunctionDef of the stubs."""
    tree = ast.parse(STUBS.read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            out[(None, node.name)] = node
        elif isinstance(node, ast.ClassDef):
            for f in node.body:
                if isinstance(f, ast.FunctionDef):
                    out[(node.name, f.name)] = f
    return out


def runtime_functions():
    out = {(None, "load"): robodyn.load, (None, "base_parameters"): robodyn.base_parameters}
    for cls in [robodyn.Robot, robodyn.ClosedChain]:
        for name, f in vars(cls).items():
            if callable(f) and not name.startswith("_"):
                out[(cls.__name__, name)] = getattr(cls, name)
    return out


def test_stubs_are_in_step_with_the_extension():
    """Every function of Robot, ClosedChain and the module has a stub with the same parameters
    (names, kinds, defaults) and a docstring; the array functions' docstrings give shapes."""
    stubs = stub_functions()
    for key, f in runtime_functions().items():
        assert key in stubs, f"{key} has no stub"
        sig = inspect.signature(f)
        params = [p for p in sig.parameters.values() if p.name != "self"]
        node = stubs[key]
        args = node.args
        pos = [a.arg for a in args.args if a.arg != "self"]
        kwonly = [a.arg for a in args.kwonlyargs]
        assert [p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.POSITIONAL_ONLY)] == pos, key
        assert [p.name for p in params if p.kind == p.KEYWORD_ONLY] == kwonly, key
        defaults = dict(zip(pos[len(pos) - len(args.defaults):], args.defaults))
        defaults.update({a.arg: d for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None})
        for p in params:
            if p.default is not inspect.Parameter.empty:
                assert p.name in defaults, (key, p.name)
                assert ast.literal_eval(defaults[p.name]) == p.default, (key, p.name)
        assert f.__doc__ and ast.get_docstring(node), f"{key}: no docstring"
    for cls in [robodyn.Robot, robodyn.ClosedChain]:
        for name in ["idm", "ddm", "regressor"] + (["inertia", "h", "forward_kinematics"] if cls is robodyn.Robot else ["solve_loops"]):
            doc = getattr(cls, name).__doc__
            assert "(N, nq" in doc or "(N nq" in doc or "(N, p)" in doc or "as idm" in doc, (cls, name)
            assert "out" in doc


def test_out_is_written_and_checked():
    robot = robodyn.load(robot_path("rx90.toml"))
    rng = np.random.default_rng(2)
    q, qd, qdd = (rng.uniform(-1, 1, (4, 6)) for _ in range(3))
    ref = robot.idm(q, qd, qdd)
    out = np.full((4, 6), np.nan)
    assert robot.idm(q, qd, qdd, out=out) is out
    np.testing.assert_array_equal(out, ref)
    one = np.empty(6)
    assert robot.idm(q[1], qd[1], qdd[1], out=one) is one
    np.testing.assert_array_equal(one, ref[1])
    a = np.empty((4, 6, 6))
    robot.inertia(q, out=a)
    np.testing.assert_array_equal(a, robot.inertia(q))
    phi = np.empty((24, len(robot.regressor_columns())))
    robot.regressor(q, qd, qdd, out=phi)
    np.testing.assert_array_equal(phi, robot.regressor(q, qd, qdd))
    # out may be an input: the input is read before it is written
    x = q.copy()
    robot.idm(x, qd, qdd, out=x)
    np.testing.assert_array_equal(x, ref)
    with pytest.raises(robodyn.DimensionError, match=r"out has shape \(4, 5\)"):
        robot.idm(q, out=np.empty((4, 5)))
    with pytest.raises(robodyn.InputError, match="float64"):
        robot.idm(q, out=np.empty((4, 6), dtype=np.float32))
    with pytest.raises(robodyn.InputError, match="C-contiguous"):
        robot.idm(q, out=np.empty((6, 4)).T)
    ro = np.empty((4, 6))
    ro.flags.writeable = False
    with pytest.raises(robodyn.InputError, match="read-only"):
        robot.idm(q, out=ro)
    with pytest.raises(robodyn.InputError, match="float64"):
        robot.idm(q, out=[0.0] * 6)
