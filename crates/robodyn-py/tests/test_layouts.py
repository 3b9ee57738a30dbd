"""Every array argument of every function is read by its logical indices, whatever its memory
layout and dtype (issue 30 item 1): a property test over layouts (C and Fortran order,
transposes, row and column strides, negative strides, broadcast rows, unaligned and byte-swapped
memory) and dtypes (float32, integers, lists), comparing each call with the same call on the
C-contiguous float64 array of the same values. The comparison is exact: the same numbers in the
same order give the same floating-point results."""

import numpy as np
import pytest

import robodyn
from conftest import robot_path

SEED = 20261126


# --- layouts: each takes a C-contiguous float64 array X (1-D or 2-D) and returns an array-like
# with the same logical values (possibly after a dtype conversion, given by `values`) --------

def fortran(x):
    return np.asfortranarray(x)


def transposed(x):
    # the transpose of a C array's transpose: Fortran-ordered memory of the same values
    return np.ascontiguousarray(x.T).T


def row_strided(x):
    if x.ndim == 1:
        big = np.zeros(2 * x.shape[0])
        big[::2] = x
        return big[::2]
    big = np.full((2 * x.shape[0], x.shape[1]), np.nan)
    big[::2] = x
    return big[::2]


def column_strided(x):
    if x.ndim == 1:
        big = np.full((x.shape[0], 3), np.nan)
        big[:, 1] = x
        return big[:, 1]  # a column of a C array: stride 3 elements
    big = np.full((x.shape[0], 2 * x.shape[1]), np.nan)
    big[:, 1::2] = x
    return big[:, 1::2]


def reversed_rows(x):
    return x[::-1].copy()[::-1]


def reversed_columns(x):
    if x.ndim == 1:
        return x[::-1].copy()[::-1]
    return x[:, ::-1].copy()[:, ::-1]


def reversed_both(x):
    if x.ndim == 1:
        return reversed_rows(x)
    return x[::-1, ::-1].copy()[::-1, ::-1]


def unaligned(x):
    buf = np.zeros(x.size * 8 + 1, dtype=np.uint8)
    a = np.frombuffer(buf.data, dtype=np.float64, count=x.size, offset=1).reshape(x.shape)
    a[...] = x
    assert not a.flags.aligned
    return a


def big_endian(x):
    return x.astype(">f8")


def as_list(x):
    return x.tolist()


def f32(x):
    return x.astype(np.float32)


def f32_fortran(x):
    return np.asfortranarray(x.astype(np.float32))


def ints(x):
    return np.round(4 * x).astype(np.int64)


def ints_strided(x):
    return column_strided(np.round(4 * x)).astype(np.int32)


LAYOUTS = [fortran, transposed, row_strided, column_strided, reversed_rows, reversed_columns,
           reversed_both, unaligned, big_endian, as_list, f32, f32_fortran, ints, ints_strided]


def reference(layout, x):
    """The C-contiguous float64 array of the values `layout(x)` holds."""
    return np.ascontiguousarray(np.asarray(layout(x), dtype=np.float64))


# --- the functions: name, (robot or chain) -> callable, the input names, shapes ---------------

def tree_calls(robot):
    n = robot.nq
    return [
        ("idm", robot.idm, 3, n),
        ("inertia", robot.inertia, 1, n),
        ("h", robot.h, 2, n),
        ("ddm", lambda q, qd, tau: robot.ddm(q, qd, tau, method="aba"), 3, n),
        ("ddm composite", lambda q, qd, tau: robot.ddm(q, qd, tau), 3, n),
        ("forward_kinematics", robot.forward_kinematics, 1, n),
        ("regressor", robot.regressor, 3, n),
        ("regressor base", lambda q, qd, qdd: robot.regressor(q, qd, qdd, columns="base"), 3, n),
    ]


def closed_calls(chain):
    n = chain.nq

    def fresh(f):
        def call(*args):
            chain.reset()  # every call from the assembly: comparable results
            return f(*args)
        return call

    return [
        ("ClosedChain.idm", fresh(chain.idm), 3, n),
        ("ClosedChain.ddm", fresh(chain.ddm), 3, n),
        ("ClosedChain.regressor", fresh(chain.regressor), 3, n),
        ("ClosedChain.solve_loops", fresh(chain.solve_loops), 1, n),
    ]


def states(rng, n, rows, center=None):
    c = np.zeros(n) if center is None else center
    shape = (n,) if rows is None else (rows, n)
    q = c + 0.05 * rng.uniform(-1, 1, shape)
    return [q, rng.uniform(-1, 1, shape), rng.uniform(-1, 1, shape)]


def usable(layout, pos, closed):
    """Integer positions of a closed chain are far from its assembly branch: q_a keeps real
    values there (integer velocities and accelerations are tested)."""
    return not (closed and pos == 0 and layout in (ints, ints_strided))


def check_all_layouts(name, f, k, inputs, closed=False):
    """Each input in turn in each layout (the others C-contiguous)."""
    base = inputs[:k]
    for pos in range(k):
        for layout in [lay for lay in LAYOUTS if usable(lay, pos, closed)]:
            args = list(base)
            ref = list(base)
            args[pos] = layout(base[pos])
            ref[pos] = reference(layout, base[pos])
            np.testing.assert_array_equal(
                f(*args), f(*ref), err_msg=f"{name}: argument {pos} as {layout.__name__}")


def check_mixes(name, f, k, inputs, rng, trials=12, closed=False):
    """Random layouts for all inputs at once (seeded)."""
    for _ in range(trials):
        chosen = [LAYOUTS[i] for i in rng.integers(0, len(LAYOUTS), k)]
        chosen = [lay if usable(lay, pos, closed) else fortran for pos, lay in enumerate(chosen)]
        args = [lay(x) for lay, x in zip(chosen, inputs[:k])]
        ref = [reference(lay, x) for lay, x in zip(chosen, inputs[:k])]
        np.testing.assert_array_equal(
            f(*args), f(*ref), err_msg=f"{name}: {[c.__name__ for c in chosen]}")


@pytest.mark.parametrize("rows", [None, 7])
@pytest.mark.parametrize("name", ["rx90.toml", "scara.toml", "torso2arms.toml", "rx90.urdf"])
def test_tree_functions_read_every_layout_by_logical_index(name, rows):
    robot = robodyn.load(robot_path(name))
    rng = np.random.default_rng(SEED)
    inputs = states(rng, robot.nq, rows)
    for fname, f, k, _ in tree_calls(robot):
        # every input changes the result: an input misread would be seen
        for pos in range(k):
            moved = [x + 0.1 * (i == pos) for i, x in enumerate(inputs[:k])]
            assert not np.array_equal(f(*moved), f(*inputs[:k])), (fname, pos)
        check_all_layouts(f"{name} {fname}", f, k, inputs)
        check_mixes(f"{name} {fname}", f, k, inputs, rng)


@pytest.mark.parametrize("rows", [None, 5])
@pytest.mark.parametrize("name", ["sr400.toml", "fivebar.toml"])
def test_closed_chain_functions_read_every_layout_by_logical_index(name, rows):
    chain = robodyn.ClosedChain(robodyn.load(robot_path(name)))
    rng = np.random.default_rng(SEED)
    qa0 = np.array(chain.branch["q_a"])
    inputs = states(rng, chain.nq, rows, center=qa0)
    if rows is not None:
        # a trajectory from the assembly: each row reachable from the previous one
        inputs[0] = qa0 + 0.02 * np.linspace(0, 1, rows)[:, None] * np.arange(1, chain.nq + 1)
    for fname, f, k, _ in closed_calls(chain):
        check_all_layouts(f"{name} {fname}", f, k, inputs, closed=True)
        check_mixes(f"{name} {fname}", f, k, inputs, rng, trials=6, closed=True)


def test_fortran_order_batch_is_not_read_as_raw_memory():
    """The case of the issue: a Fortran-ordered batch gave torques off by up to 40 N m."""
    robot = robodyn.load(robot_path("rx90.toml"))
    q = np.random.default_rng(1).uniform(-1, 1, (5, 6))
    raw = np.asfortranarray(q).ravel(order="K").reshape(5, 6)  # what the old reader used
    assert not np.allclose(robot.idm(raw), robot.idm(q))  # the two readings differ
    np.testing.assert_array_equal(robot.idm(np.asfortranarray(q)), robot.idm(q))
    np.testing.assert_array_equal(robot.idm(q.T.copy().T), robot.idm(q))


def test_broadcast_rows_are_read_in_place():
    robot = robodyn.load(robot_path("rx90.toml"))
    q = np.linspace(-0.5, 0.5, 6)
    many = np.broadcast_to(q, (1000, 6))  # stride 0 between rows: no memory behind the rows
    tau = robot.idm(many, many, many)
    np.testing.assert_array_equal(tau, np.tile(robot.idm(q, q, q), (1000, 1)))


def test_one_state_vectors_of_other_layouts():
    """One-state (1-D) arguments of the functions that take sequences: the closed chain's
    closure and reset, simulation inputs (q0, qd0, a constant torque, a torque series)."""
    chain = robodyn.ClosedChain(robodyn.load(robot_path("sr400.toml")))
    qa = np.array(chain.branch["q_a"]) + 0.03
    for layout in [row_strided, column_strided, reversed_rows, f32, big_endian, as_list]:
        chain.reset()
        a = chain.closure(layout(qa))
        chain.reset()
        b = chain.closure(reference(layout, qa))
        np.testing.assert_array_equal(a["q_p"], b["q_p"], err_msg=layout.__name__)
    robot = robodyn.load(robot_path("rx90.toml"))
    q0 = np.linspace(0.1, 0.6, 6)
    tau = np.linspace(1.0, -1.0, 6)
    ref = robot.simulate(0.05, q0=q0, qd0=q0, torque=tau, dt=1e-3, output_dt=0.01)
    times = np.array([0.0, 1.0])
    series = np.array([tau, tau])
    for layout in [row_strided, column_strided, reversed_rows, big_endian]:
        out = robot.simulate(0.05, q0=layout(q0), qd0=layout(q0), torque=layout(tau), dt=1e-3,
                             output_dt=0.01)
        np.testing.assert_array_equal(out["q"], ref["q"], err_msg=layout.__name__)
    for layout in [fortran, transposed, reversed_both, column_strided]:
        out = robot.simulate(0.05, q0=q0, qd0=q0, torque=(times, layout(series)), dt=1e-3,
                             output_dt=0.01)
        np.testing.assert_array_equal(out["q"], ref["q"], err_msg=layout.__name__)
