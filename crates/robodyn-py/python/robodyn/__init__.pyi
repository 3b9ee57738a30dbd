"""robodyn: dynamic models of robots with complex structure (trees and closed kinematic chains)
in the Khalil-Kleinfinger notation (Khalil & Dombre, chapter 10), on NumPy arrays.

Joint vectors hold the movable joints in frame order (``Robot.joint_names``); for a
``ClosedChain`` they hold the actuated joints. Units: rad and m, rad/s and m/s, rad/s^2 and m/s^2,
N m and N. Every model function takes one state (1-D arrays) or N states (2-D arrays, one row per
state); N states are evaluated in Rust over all cores with the GIL released.
"""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]
Torque = Union[None, ArrayLike, Tuple[ArrayLike, ArrayLike], Callable[[float, Array, Array], ArrayLike]]

__version__: str

class Error(Exception):
    """Base class of every robodyn error. ``row`` is the 1-based row of a batch that failed (None for one state)."""
    row: Optional[int]

class RobotFileError(Error):
    """A robot file or description is invalid or cannot be read."""
    file: Optional[str]
    line: Optional[int]
    column: Optional[int]
    item: str
    reason: str

class PhysicalParameterError(RobotFileError):
    """A physically inconsistent parameter (negative mass, rotor inertia or friction)."""

class DimensionError(Error):
    """An array of the wrong shape or size; the message names the expected shape."""
    what: str
    expected: int
    got: int

class NotFiniteError(Error):
    """A NaN or infinite input."""
    what: str
    index: int
    value: float

class SingularConfiguration(Error):
    """A singular configuration: Wp, A_cl or A below its hard conditioning limit."""
    what: str
    rcond: float

class LoopClosureError(Error):
    """The loop-closure equations have no solution near the guess."""

class BranchLost(LoopClosureError):
    """The actuated values cannot be reached on the tracker's assembly branch."""

class InputError(Error):
    """Other input that does not fit the robot (bad option, wrong count)."""

class NumericalError(Error):
    """A numerical failure (no convergence, step-size underflow...)."""

class SingularityWarning(UserWarning):
    """A result near a singular configuration (reciprocal condition number below the soft limit)."""

def load(path: Union[str, PathLike], **values: float) -> Robot:
    """Read a robot file (TOML, SYMORO .par or URDF, by extension); ``values`` give or change
    symbol values (``robodyn.load("robots/sr400.toml", d3=0.6)``). Raises RobotFileError with
    the file and line of a bad entry; for a file whose symbols lack values (a SYMORO file of
    symbols only) the message lists them: give them as keyword arguments, or use
    ``base_parameters(path)``, which needs none."""

def base_parameters(path: Union[str, PathLike], method: str = "symbolic", friction: bool = True, rotor: str = "actuated", zeros: Optional[str] = None, seed: int = 1, **values: float) -> BaseParameters:
    """Base inertial parameters of a robot file, with or without numeric values (the CLI's
    ``robodyn base-params``): method "symbolic" works on the symbols; "numeric" and "both" take
    generic values for geometry symbols without one (said in ``notes``: the count and grouping
    then hold for generic geometry, and ``coefficients`` is None). ``values`` give symbol values.
    For a loaded robot, ``Robot.base_parameters`` is the same on its values."""

class Robot:
    """A robot model: a tree, or the equivalent tree of a closed chain (use ``ClosedChain(robot)``
    for the closed-chain models). Vectors hold the movable joints in frame order."""

    @staticmethod
    def from_toml_str(text: str) -> Robot:
        """Read a robot from TOML text (the format of docs/robot-format.md)."""
    name: str
    """Robot name."""
    nq: int
    """Number of movable joints: the length of every joint vector (q, qd, qdd, tau)."""
    nl: int
    """NL, number of links (and of tree joints)."""
    nj: int
    """NJ, number of joints (NJ - NL cut joints)."""
    nf: int
    """NF, number of frames (2 NJ - NL)."""
    joint_names: List[str]
    """Names of the movable joints, in the order of every joint vector."""
    joint_frames: List[int]
    """Frame numbers (1-based) of the movable joints, in vector order."""
    frame_names: List[str]
    """Names of the frames 1..NF (fixed frames and cut-joint twins included)."""
    link_names: List[str]
    """Names of the links 1..NL."""
    antecedents: List[int]
    """Antecedents a(j) of the frames 1..NF (0 is the base)."""
    actuated: List[int]
    """Frame numbers of the actuated joints."""
    passive: List[int]
    """Frame numbers of the passive joints (tree joints and cut joints)."""
    is_tree: bool
    """Whether the structure is a tree (no closed loop)."""
    loops: List[Dict[str, Any]]
    """The closed loops: cut, twin, link_i, link_j, root, branch_i, branch_j."""
    symbols: Dict[str, float]
    """The symbols of the description and their values."""
    assembly: Optional[List[float]]
    """The assembly configuration (tree joints 1..NL) of a closed robot, or None."""
    standard_parameters: List[float]
    """Standard parameters K (13 per link: XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV)."""
    parameter_names: List[str]
    """Names of the standard parameters (the robot file's own names), in K order."""

    def set(self, **values: float) -> None:
        """Give or change symbol values in place: ``robot.set(d3=0.45, M2=10.0)``."""
    def with_values(self, **values: float) -> Robot:
        """A new robot with symbol values given or changed (this one unchanged)."""
    def save(self, path: Union[str, PathLike]) -> None:
        """Write the description (format by extension: .toml or .par)."""
    def to_toml(self) -> str:
        """The description as TOML text."""

    def idm(self, q: ArrayLike, qd: Optional[ArrayLike] = None, qdd: Optional[ArrayLike] = None) -> Array:
        """Inverse dynamic model (Newton-Euler, eqs 10.3-10.12): torques of the movable joints,
        (nq,) or (N, nq). Friction (Fv qd + Fs sign(qd)) and rotor inertias included; missing
        qd, qdd are zero."""
    def inertia(self, q: ArrayLike) -> Array:
        """Inertia matrix A(q) by composite links: (nq, nq) or (N, nq, nq)."""
    def h(self, q: ArrayLike, qd: Optional[ArrayLike] = None) -> Array:
        """H(q, qd): centrifugal, Coriolis, gravity, friction and external-wrench torques."""
    def ddm(self, q: ArrayLike, qd: Optional[ArrayLike] = None, tau: Optional[ArrayLike] = None, method: str = "composite") -> Array:
        """Direct dynamic model qdd = A^-1 (tau - H): method "composite" (tree L'DL of A) or
        "aba" (O(n) articulated bodies). Raises SingularConfiguration for a singular A."""
    def forward_kinematics(self, q: ArrayLike) -> Array:
        """Geometric model: 0T_j (4 x 4 homogeneous matrices) of the frames 1..NF (``frame_names``)
        for the movable joints' values q, cut-joint variables taken as 0: (NF, 4, 4) or
        (N, NF, 4, 4)."""
    def regressor_columns(self, columns: str = "standard", friction: bool = True, rotor: str = "actuated", seed: int = 1) -> List[str]:
        """Names of the regressor's columns: "standard" parameters or "base" parameters."""
    def regressor(self, q: ArrayLike, qd: Optional[ArrayLike] = None, qdd: Optional[ArrayLike] = None, columns: str = "standard", friction: bool = True, rotor: str = "actuated", seed: int = 1) -> Array:
        """Regressor Phi with Gamma = Phi K (+ external-wrench torques): (nq, p) for one state,
        stacked (N nq, p) for N states (state after state); columns are ``regressor_columns``."""
    def base_parameters(self, method: str = "symbolic", friction: bool = True, rotor: str = "actuated", zeros: Optional[str] = None, seed: int = 1) -> BaseParameters:
        """Base inertial parameters: method "symbolic" (rules, equations in the robot's symbols),
        "numeric" (stacked regressor, rank-revealing QR) or "both" (symbolic, checked against the
        numeric set). rotor: "actuated", "all" or "none"; zeros: what a literal 0 means
        ("absent" for SYMORO .par files by default, else "value")."""
    def generate(self, model: str = "idm", lang: str = "python", params: str = "standard", symmetric: bool = False, friction: bool = True, rotor: bool = True, numeric: bool = False, name: Optional[str] = None) -> Generated:
        """Customized symbolic model (idm, inertia, h, ddm, closed, w) as code (text, latex,
        rust, c, python, julia, matlab) with its operation counts; params "standard" or "base"."""
    def simulate(self, duration: float, q0: Optional[Sequence[float]] = None, qd0: Optional[Sequence[float]] = None, torque: Torque = None, dt: Optional[float] = None, rtol: float = 1e-8, atol: float = 1e-10, output_dt: float = 0.01, method: str = "aba", coulomb_smoothing: Optional[float] = None, max_steps: Optional[int] = None) -> Dict[str, Any]:
        """Simulate from (q0, qd0) over [0, duration]: dict of arrays t (M,), q, qd, qdd, tau
        (M, nq), energy (M,). torque: None (zero), a constant vector, a (times, values) series
        interpolated linearly, or a callable torque(t, q, qd) -> tau. RK4 with ``dt``, else
        Dormand-Prince 5(4) with rtol, atol."""

class ClosedChain:
    """A closed-chain robot: vectors over the actuated joints (``joint_names``); the passive ones
    are solved by loop closure on the tracker's assembly branch. Every evaluation moves the
    tracker (held by this object) from its last point to the new q_a by continuation; the rows
    of N states are evaluated in order on that one branch. Results near a singularity give a
    SingularityWarning; at a singularity SingularConfiguration; a q_a not reachable on the
    branch BranchLost."""

    def __init__(self, robot: Robot, q_a: Optional[Sequence[float]] = None, q_p_guess: Optional[Sequence[float]] = None) -> None:
        """The closed-chain model of ``robot``, its tracker on the branch of the robot's
        assembly (or on the branch through (q_a, q_p_guess))."""
    joint_names: List[str]
    """Names of the actuated joints: the order of every vector of the closed-chain models."""
    joint_frames: List[int]
    """Frame numbers of the actuated joints."""
    passive_names: List[str]
    """Names of the passive tree joints (the order of q_p)."""
    nq: int
    """Degrees of freedom (actuated joints)."""
    n_equations: int
    """Number of independent closure equations (= passive tree joints)."""
    robot: Robot
    """The equivalent tree."""
    branch: Dict[str, Any]
    """The tracker's point: q_a, q_p, det_sign (the branch), rcond of Wp."""

    def reset(self, q_a: Optional[Sequence[float]] = None, q_p_guess: Optional[Sequence[float]] = None) -> None:
        """Put the tracker back on the assembly branch (or on the branch through (q_a, q_p_guess))."""
    def solve_loops(self, q_a: ArrayLike) -> Array:
        """Loop closure: the passive tree variables q_p for the actuated q_a, (p,) or (N, p)."""
    def closure(self, q_a: Sequence[float]) -> Dict[str, Any]:
        """Loop closure at one q_a: q_p, cut-joint variables q_c, the tree's movable-joint vector
        q_tree, W = d q_p / d q_a (eq 10.30), residual, rcond_wp, warning."""
    def idm(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, qdd_a: Optional[ArrayLike] = None) -> Array:
        """Closed-chain inverse dynamic model Gamma_cl = G^T Gamma_tr (eq 10.40) on the actuated joints."""
    def ddm(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, tau_a: Optional[ArrayLike] = None) -> Array:
        """Closed-chain direct dynamic model qdd_a = A_cl^-1 (Gamma_cl - H_cl) (eqs 10.46-10.48)."""
    def regressor(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, qdd_a: Optional[ArrayLike] = None) -> Array:
        """Regressor G^T Phi over all 13 NL standard parameters (K order): (nq, 13 NL) for one
        state, stacked (N nq, 13 NL) for N states."""
    def simulate(self, duration: float, q0: Optional[Sequence[float]] = None, qd0: Optional[Sequence[float]] = None, torque: Torque = None, dt: Optional[float] = None, rtol: float = 1e-8, atol: float = 1e-10, output_dt: float = 0.01, coulomb_smoothing: Optional[float] = None, max_steps: Optional[int] = None) -> Dict[str, Any]:
        """Simulate in the actuated coordinates from (q0, qd0) (default: the tracker's q_a, 0);
        q_p is re-solved at every evaluation. Returns t, q, qd, qdd, tau, energy,
        closure_residual and the passive joints' q<j>."""

class BaseParameters:
    """Base inertial parameters by one method (section 10.2.4, 10.3.4-10.3.6)."""
    method: str
    names: List[str]
    """Names of the base parameters (the robot's names, R suffix when grouped: XXR2)."""
    indices: List[int]
    """Their indices in K (13 per link, 0-based)."""
    regrouped: List[bool]
    equations: List[str]
    """Grouping equations (right-hand sides) as text in the robot's names."""
    values: List[Optional[float]]
    """Values for the robot's numbers (None where a parameter involved has no value)."""
    columns: List[str]
    """Standard parameters of the model (selected and existing): the columns of ``coefficients``."""
    coefficients: Optional[Array]
    """Coefficient table (n_base x len(columns)): K_base = coefficients @ K[columns]."""
    no_effect: List[str]
    grouped: List[str]
    notes: List[str]
    table: List[List[str]]
    """The per-link table like Table 10.2."""
    report: str
    """The report as text (what ``robodyn base-params`` prints)."""
    json: str
    """The report as JSON text."""
    def __len__(self) -> int: ...

class Generated:
    """A generated customized model."""
    name: str
    code: str
    multiplications: int
    additions: int
    functions: int
