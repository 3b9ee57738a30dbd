"""robodyn: dynamic models of robots with complex structure (trees and closed kinematic chains)
in the Khalil-Kleinfinger notation (Khalil & Dombre, chapter 10), on NumPy arrays.

Joint vectors hold the movable joints in frame order (``Robot.joint_names``); for a
``ClosedChain`` they hold the actuated joints. Units: rad and m, rad/s and m/s, rad/s^2 and m/s^2,
N m and N. Every model function takes one state (1-D arrays) or N states (2-D arrays, one row per
state); N states are evaluated in Rust over all cores with the GIL released (Ctrl-C interrupts).
Arrays of any layout and dtype are read by their logical indices (float64 arrays with contiguous
rows in place, others converted); ``out=`` writes into a float64 C-contiguous writeable array.
"""

from os import PathLike
from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

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

class RobotFileWarning(UserWarning):
    """What a robot file's reader noticed that is not an error (inertial parameters no rigid body
    has, a legged robot loaded with a fixed base, ...)."""

def load(path: Union[str, PathLike], *, floating: bool = False, **values: float) -> Robot:
    """Read a robot file (TOML, SYMORO .par or URDF, by extension). ``values`` give or change
    values by name: symbols (``robodyn.load("robots/sr400.toml", d3=0.6)``) or standard
    parameters the file writes as numbers (``load("ur5.urdf", M3=3.2, FV2=0.5)``: mass of link 3
    in kg, viscous friction of joint 2 in N m s/rad; names as ``Robot.parameter_names``); an
    unknown name raises InputError listing the known ones. What the reader notices is issued as
    a RobotFileWarning. Raises RobotFileError with the file and line of a bad entry; for a file
    whose symbols lack values (a SYMORO file of symbols only) the message lists them: give them
    as keyword arguments, or use ``base_parameters(path)``, which needs none.

    ``floating=True`` makes the base floating: a URDF's root link becomes link 0 of a free-flyer
    base with its ``<inertial>`` (Pinocchio's ``JointModelFreeFlyer`` root); the state vectors
    then have nq = 7 + N (q: base position, quaternion x y z w, joints) and nv = 6 + N entries.
    A .toml or .par file says it itself (``base = "floating"``, ``is_floating = 1``)."""

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
    """nq, the length of a configuration q: the number of movable joints on a fixed (or mobile)
    base, 7 + that on a floating base (base position, quaternion x y z w, joints)."""
    nv: int
    """nv, the length of qd, qdd and tau: the number of movable joints, 6 + that on a floating
    base (base linear and angular velocity in the base frame, joints)."""
    dof: int
    """Number of movable joints (nq = nv = dof on a fixed base)."""
    is_floating: bool
    """Whether the base floats (a free body moved by the dynamics; Pinocchio's free-flyer)."""
    base_kind: str
    """What moves the base: "fixed", "mobile" (its motion imposed) or "floating"."""
    configuration_names: List[str]
    """Names of the nq entries of q (base_x, base_y, base_z, base_qx .. base_qw first on a
    floating base, then the joint names)."""
    velocity_names: List[str]
    """Names of the nv entries of qd, qdd and tau (base_vx .. base_wz first on a floating base,
    then the joint names)."""
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
    """Every frame name placement, jacobian, frame_velocity, ... accept, each once: tools (the
    body frames of URDF links), links, then the description's frames (joint names; cut-joint
    frames left out). The numbers "0".."NF" are accepted too."""
    description_frame_names: List[str]
    """Names of the description's frames 1..NF in frame order (fixed frames, cut joints and
    their twins included): the frames of forward_kinematics and antecedents."""
    mass: float
    """Total mass (kg) of the links a joint moves (what com weighs)."""
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
        """Give or change values by name, in place: symbols (``robot.set(d3=0.45)``) or standard
        parameters the file writes as numbers (``robot.set(M3=12.0, FS2=0.5)``: mass of link 3 in
        kg, Coulomb friction of joint 2 in N m; names as ``parameter_names``). An unknown name
        raises InputError listing the known ones; nothing changes then."""
    def with_values(self, **values: float) -> Robot:
        """A new robot with values given or changed by name as ``set`` does (this one unchanged):
        ``urdf_robot.with_values(M3=12.0)`` changes the mass of link 3 (kg)."""
    def save(self, path: Union[str, PathLike]) -> None:
        """Write the description (format by extension: .toml or .par)."""
    def view(self, q: Optional[Sequence[float]] = None, trajectory: Optional[Union[str, PathLike, Tuple[Sequence[float], ArrayLike]]] = None, names: str = "frame") -> View:
        """A 3D view of the robot (the page of ``robodyn view``): every frame's x and z axes
        labelled j, the links along the geometric parameters, joints, fixed frames, cut joints
        and their twin frames, the base and gravity, URDF meshes (STL) when found. ``q``: the
        movable joints (rad or m), or a closed robot's actuated joints (passive joints by loop
        closure); default q = 0, or a closed robot's assembly. ``trajectory``: a CSV file
        (column ``t`` and ``q<j>``, or ``q_<name>`` with ``names="joint"``), or a pair
        ``(t, Q)``, one row of Q (N, nq) per time in s. Returns a ``View`` (``.save(path)``,
        shown inline in Jupyter)."""
    def to_toml(self) -> str:
        """The description as TOML text."""

    def idm(self, q: ArrayLike, qd: Optional[ArrayLike] = None, qdd: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, a: Optional[ArrayLike] = None, friction: bool = True, out: Optional[Array] = None) -> Array:
        """Inverse dynamic model (Newton-Euler, eqs 10.3-10.12): the torques (N m) / forces (N)
        tau of the movable joints for positions q (rad, m), velocities qd (rad/s, m/s) and
        accelerations qdd (rad/s^2, m/s^2), under the robot's gravity and wrenches.

        Shapes: (nq,) for one state, (N, nq) for N states (the result likewise). On a floating
        base q has nq entries, qd, qdd and the result nv: the result is the wrench on the base
        (force, then moment about its origin, in the base frame) then the joint torques
        (Pinocchio's rnea with a free-flyer root). Omitted qd, qdd are zeros; v and a are Pinocchio's names for qd and qdd. Friction Fv qd + Fs sign(qd)
        (URDF <dynamics damping friction>) and rotor inertias Ia qdd are included; friction=False
        leaves out Fv and Fs (Pinocchio's rnea). out: a float64 C-contiguous writeable array of
        the result's shape to write into (returned)."""
    def inertia(self, q: ArrayLike, *, out: Optional[Array] = None) -> Array:
        """Inertia matrix A(q) by composite links (kg m^2, kg, kg m): (nq, nq) for q of shape
        (nq,), (N, nq, nq) for (N, nq); rotor inertias on the diagonal. On a floating base
        (nv, nv) for q of nq entries: base block, base rows, joints (Pinocchio's crba). out: as
        for idm."""
    def h(self, q: ArrayLike, qd: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, friction: bool = True, out: Optional[Array] = None) -> Array:
        """H(q, qd) (N m, N): centrifugal, Coriolis, gravity, friction and external-wrench
        torques, so that tau = A(q) qdd + H(q, qd). Shapes as idm (nv entries on a floating
        base); v is Pinocchio's name for qd
        (Pinocchio's nonLinearEffects, plus friction unless friction=False). out: as for idm."""
    def ddm(self, q: ArrayLike, qd: Optional[ArrayLike] = None, tau: Optional[ArrayLike] = None, method: str = "composite", *, v: Optional[ArrayLike] = None, friction: bool = True, out: Optional[Array] = None) -> Array:
        """Direct dynamic model: accelerations qdd (rad/s^2, m/s^2) = A^-1 (tau - H) for
        positions q, velocities qd and torques tau (N m, N); method "composite" (tree L'DL of A)
        or "aba" (articulated bodies). Shapes as idm; on a floating base tau's 6 first entries
        are the wrench applied on the base (zero for a free robot) and the result's 6 first the
        derivative of the base twist (Pinocchio's aba). v is Pinocchio's name for qd.
        friction=False leaves out Fv and Fs (Pinocchio's aba). Raises SingularConfiguration for
        a singular A. out: as for idm."""
    def integrate(self, q: ArrayLike, v: ArrayLike, dt: float, *, out: Optional[Array] = None) -> Array:
        """The configuration reached from q (nq,) moving at the constant velocity v (nv,) for dt
        seconds (Pinocchio's integrate(model, q, v dt)): a floating base moves on SE(3), its
        placement M exp(v dt) with the twist in the base frame, so the quaternion stays a unit
        quaternion; the joints move by v dt (on a fixed base, q + v dt). Shapes (nq,) and (nv,),
        or (N, nq) and (N, nv); the result has q's shape. out: as for idm."""
    def centroidal_momentum(self, q: ArrayLike, v: Optional[ArrayLike] = None) -> Dict[str, Any]:
        """Mass, centre of mass and centroidal momentum of a floating robot at q (nq,) and v
        (nv,): a dict with "mass" (kg), "com" (3,) (m), "linear" (3,) (kg m/s) and "angular"
        (3,) (kg m^2/s, about the centre of mass), world components (Pinocchio's
        computeCentroidalMomentum: data.com[0], data.hg). N states (N, nq), (N, nv) give arrays
        with a leading N. InputError on a robot that does not float."""
    def centroidal_map(self, q: ArrayLike, *, out: Optional[Array] = None) -> Array:
        """The centroidal momentum matrix A_G(q) of a floating robot (Pinocchio's
        computeCentroidalMap / ccrba's data.Ag): h_G = A_G v, rows [linear momentum; angular
        momentum about the centre of mass] in world components, columns over v. Shape (6, nv)
        for q of shape (nq,), (N, 6, nv) for (N, nq). InputError on a robot that does not
        float. out: as for idm."""
    def idm_derivatives(self, q: ArrayLike, qd: Optional[ArrayLike] = None, qdd: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, a: Optional[ArrayLike] = None, friction: bool = True) -> Tuple[Array, Array, Array]:
        """Derivatives of the inverse dynamic model (analytical, docs/models/derivatives.md):
        (dtau_dq, dtau_dqd, A) with A = dtau/dqdd the inertia matrix, each (nq, nq) for one
        state, (N, nq, nq) for N states (q, qd, qdd of shape (N, nq)); entry [j, k] is the
        derivative of tau_j with respect to joint k. Arguments as idm (Coulomb friction has a
        zero derivative, viscous friction adds Fv on dtau_dqd's diagonal; friction=False leaves
        both out: Pinocchio's computeRNEADerivatives)."""
    def ddm_derivatives(self, q: ArrayLike, qd: Optional[ArrayLike] = None, tau: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, friction: bool = True) -> Tuple[Array, Array, Array]:
        """Derivatives of the direct dynamic model at qdd = ddm(q, qd, tau) (composite method):
        (dqdd_dq, dqdd_dqd, Ainv) with Ainv = dqdd/dtau = A^-1, from the one L'DL factorization
        of A. Shapes as idm_derivatives; arguments as ddm (friction=False: Pinocchio's
        computeABADerivatives). Raises SingularConfiguration for a singular A."""
    def forward_kinematics(self, q: ArrayLike, *, out: Optional[Array] = None) -> Array:
        """Geometric model: 0T_j (4 x 4 homogeneous matrices, metres) of the frames 1..NF
        (description_frame_names) for the movable joints' values q (rad, m; cut-joint variables taken as
        0): shape (NF, 4, 4) for q of shape (nq,), (N, NF, 4, 4) for (N, nq). out: as for idm."""
    def placement(self, q: ArrayLike, frame: str, *, out: Optional[Array] = None) -> Array:
        """Placement 0T_f of the frame named ``frame`` (a name of ``frame_names``: URDF link or
        joint, tool, link, or a frame number "0".."NF"): a 4 x 4 homogeneous matrix (metres) for
        q (rad, m) of shape (nq,), (N, 4, 4) for (N, nq) (Pinocchio's data.oMf). Raises
        InputError for an unknown frame (with the near names). out: as for idm."""
    def jacobian(self, q: ArrayLike, frame: str, reference: str = "world", *, out: Optional[Array] = None) -> Array:
        """Jacobian of the frame named ``frame`` in ``reference``: "world", "local" or
        "local_world_aligned" (Pinocchio's WORLD, LOCAL, LOCAL_WORLD_ALIGNED). Rows [linear;
        angular]: shape (6, nq) for q of shape (nq,), (N, 6, nq) for (N, nq). An unknown
        reference raises ValueError. out: as for idm."""
    def jacobian_time_variation(self, q: ArrayLike, qd: ArrayLike, frame: str, reference: str = "world", *, out: Optional[Array] = None) -> Array:
        """Time variation dJ/dt of the frame's Jacobian in `reference` (as jacobian) at q, qd
        (Pinocchio's getFrameJacobianTimeVariation): J̇ qd + J qdd is the frame's acceleration in
        that reference. Shape (6, nv) for one state, (N, 6, nv) for N states."""
    def frame_velocity(self, q: ArrayLike, qd: ArrayLike, frame: str, reference: str = "world", *, out: Optional[Array] = None) -> Array:
        """Velocity [linear; angular] (m/s, rad/s) of the frame named ``frame`` in ``reference``
        (as jacobian), J(q) qd: shape (6,) for one state, (N, 6) for N states (N, nq). out: as
        for idm."""
    def frame_acceleration(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, frame: str, reference: str = "world", *, out: Optional[Array] = None) -> Array:
        """Classical acceleration [linear; angular] (m/s^2, rad/s^2) of the frame named ``frame``
        in ``reference`` (Pinocchio's getFrameClassicalAcceleration): shape (6,) for one state,
        (N, 6) for N states (N, nq). out: as for idm."""
    def com(self, q: ArrayLike, *, out: Optional[Array] = None) -> Array:
        """Centre of mass (m, base frame) of the links a joint moves: shape (3,) for q of shape
        (nq,), (N, 3) for (N, nq). out: as for idm."""
    def com_jacobian(self, q: ArrayLike, *, out: Optional[Array] = None) -> Array:
        """Jacobian of the centre of mass: shape (3, nq) for q of shape (nq,), (N, 3, nq) for
        (N, nq). out: as for idm."""
    def ik(self, frame: str, target: ArrayLike, q0: Optional[ArrayLike] = None) -> Dict[str, Any]:
        """Inverse geometric model of the frame named ``frame`` for ``target`` (4 x 4).
        Without ``q0``: the closed form (6R, spherical wrist or axes 2, 3, 4 parallel), every
        solution: a dict "q" (S, nq) (joints off the chain are 0), "within_limits", "singular",
        "shoulder", "elbow", "wrist" (S,) bool, "joints" (the chain's 6 indices in q), "class";
        InputError when the chain has no closed form. With ``q0`` (nq,): the numeric model
        (Levenberg-Marquardt from q0, then seeded random starts; any robot): a dict "q" (nq,),
        "converged", "position_error" (m), "rotation_error" (rad), "iterations", "starts";
        batched with ``target`` (N, 4, 4) and ``q0`` (N, nq) (arrays with a leading N)."""
    def regressor_columns(self, columns: str = "standard", friction: bool = True, rotor: str = "actuated", seed: int = 1) -> List[str]:
        """Names of the regressor's columns for ``columns`` ("standard" or "base")."""
    def regressor(self, q: ArrayLike, qd: Optional[ArrayLike] = None, qdd: Optional[ArrayLike] = None, columns: str = "standard", friction: bool = True, rotor: str = "actuated", seed: int = 1, *, v: Optional[ArrayLike] = None, a: Optional[ArrayLike] = None, out: Optional[Array] = None) -> Array:
        """Regressor Phi with tau = Phi K (+ external-wrench torques) for q (rad, m), qd, qdd
        (v, a: Pinocchio's names): shape (nq, p) for one state, stacked (N nq, p) for N states
        (state after state); its columns are ``regressor_columns(columns, ...)``, the standard
        parameters (K, 13 per link) or the base parameters; entries in N m (N) per unit of the
        parameter. friction=False leaves out the FS, FV columns. out: as for idm."""
    def base_parameters(self, method: str = "symbolic", friction: bool = True, rotor: str = "actuated", zeros: Optional[str] = None, seed: int = 1) -> BaseParameters:
        """Base inertial parameters: method "symbolic" (rules, equations in the robot's symbols),
        "numeric" (stacked regressor, rank-revealing QR) or "both" (symbolic, checked against the
        numeric set). rotor: "actuated", "all" or "none"; zeros: what a literal 0 means
        ("absent" for SYMORO .par files by default, else "value")."""
    def generate(self, model: str = "idm", lang: str = "python", params: str = "standard", symmetric: bool = False, friction: bool = True, rotor: bool = True, numeric: bool = False, name: Optional[str] = None) -> Generated:
        """Customized symbolic model (idm, idm_derivatives, inertia, h, ddm, closed, w) as code (text, latex,
        rust, c, python, julia, matlab) with its operation counts; params "standard" or "base"."""
    def simulate(self, duration: float, q0: Optional[ArrayLike] = None, qd0: Optional[ArrayLike] = None, torque: Torque = None, dt: Optional[float] = None, rtol: float = 1e-8, atol: float = 1e-10, output_dt: float = 0.01, method: str = "aba", coulomb_smoothing: Optional[float] = None, max_steps: int = 5_000_000) -> Dict[str, Any]:
        """Simulate from (q0, qd0) (rad, m; rad/s, m/s; default zeros) over [0, duration] (s);
        returns a dict of arrays: t (M,) s, q (M, nq), qd, qdd, tau (M, nv), energy (M,) J,
        joint_labels, q_columns and v_columns. torque: None (zero), a constant vector (n,)
        N m / N, a (times, values) series ((K,), (K, n)) interpolated linearly, or a callable
        torque(t, q, qd) -> tau. A floating robot: q0 (nq,) (default: base at the origin,
        identity quaternion, joints zero), qd0 (nv,); torques of the n joints (the base free) or
        nv values whose first 6 are a wrench on the base (base frame); the base pose is
        integrated on SE(3); the dict adds the centre of mass and the momenta. RK4 with a fixed step dt (s), else Dormand-Prince 5(4) with rtol, atol; a row every
        output_dt (s). max_steps (the CLI's default, 5,000,000) bounds the integration steps: a
        run that needs more is an error, said before it starts when the step or the output step
        already needs more. Ctrl-C stops the run (KeyboardInterrupt)."""

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
    def solve_loops(self, q_a: ArrayLike, *, out: Optional[Array] = None) -> Array:
        """Loop closure: the passive tree variables q_p (rad, m) for the actuated q_a (rad, m):
        (p,) for q_a of shape (nq,), (N, p) for (N, nq), p = n_equations. out: as for idm."""
    def closure(self, q_a: ArrayLike) -> Dict[str, Any]:
        """Loop closure at one q_a (nq,): q_p, cut-joint variables q_c, the tree's movable-joint
        vector q_tree (rad, m), W = d q_p / d q_a (eq 10.30, (p, nq)), residual, rcond_wp,
        warning."""
    def jacobian(self, q_a: ArrayLike, frame: str, reference: str = "world", *, out: Optional[Array] = None) -> Array:
        """Jacobian J_a = J_tr G of the frame named ``frame`` in the actuated coordinates, in
        ``reference`` (as Robot.jacobian): the frame's velocity is J_a qd_a on the closure
        manifold. Shape (6, nq) for q_a of shape (nq,), (N, 6, nq) for (N, nq) (rows followed in
        order on one branch). out: as for idm."""
    def drift(self, q_a: ArrayLike, qd_a: ArrayLike, frame: str, reference: str = "world", *, out: Optional[Array] = None) -> Array:
        """Drift J̇_a qd_a of the frame named `frame` in `reference` (as jacobian): the derivative
        of the frame's velocity J_a qd_a on the closure manifold is J_a qdd_a + J̇_a qd_a.
        [linear; angular] (m/s², rad/s²): shape (6,) for one state, (N, 6) for (N, nq)."""
    def idm(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, qdd_a: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, a: Optional[ArrayLike] = None, out: Optional[Array] = None) -> Array:
        """Closed-chain inverse dynamic model Gamma_cl = G^T Gamma_tr (eq 10.40): the torques
        (N m) / forces (N) of the actuated joints for their positions q_a (rad, m), velocities
        qd_a and accelerations qdd_a (v, a: Pinocchio's names), the passive joints solved by
        loop closure. Shapes (nq,) or (N, nq) (rows followed in order on one branch). out: a
        float64 C-contiguous writeable array of the result's shape to write into (returned)."""
    def ddm(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, tau_a: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, out: Optional[Array] = None) -> Array:
        """Closed-chain direct dynamic model qdd_a = A_cl^-1 (Gamma_cl - H_cl) (eqs 10.46-10.48):
        the accelerations (rad/s^2, m/s^2) of the actuated joints for q_a, qd_a (v: Pinocchio's
        name) and their torques tau_a (N m, N). Shapes as idm. out: as for idm."""
    def idm_derivatives(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, qdd_a: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, a: Optional[ArrayLike] = None) -> Tuple[Array, Array, Array]:
        """Derivatives of the closed-chain inverse dynamic model (docs/models/derivatives.md,
        C1-C9): (dtau_dq, dtau_dqd, A_cl), the derivatives of Gamma_cl with respect to q_a, qd_a
        and qdd_a with the loops kept closed on the branch (entry [j, k]: of tau_a,j with respect
        to joint k), exact (the tree's analytical derivatives and dual numbers through the
        closure). Shapes (nq, nq) each for one state, (N, nq, nq) for N states (rows followed in
        order on one branch). Arguments as idm."""
    def ddm_derivatives(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, tau_a: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None) -> Tuple[Array, Array, Array]:
        """Derivatives of the closed-chain direct dynamic model at qdd_a = ddm(q_a, qd_a, tau_a)
        (C10-C11): (dqdd_dq, dqdd_dqd, Ainv) with Ainv = dqdd_a/dtau_a = A_cl^-1, from the
        Cholesky factor of the closed direct model. Shapes as idm_derivatives; arguments as ddm."""
    def regressor(self, q_a: ArrayLike, qd_a: Optional[ArrayLike] = None, qdd_a: Optional[ArrayLike] = None, *, v: Optional[ArrayLike] = None, a: Optional[ArrayLike] = None, out: Optional[Array] = None) -> Array:
        """Regressor of the closed chain, G^T Phi over all 13 NL standard parameters (K order,
        ``robot.parameter_names``): (nq, 13 NL) for one state, stacked (N nq, 13 NL) for N
        states, for q_a, qd_a, qdd_a (v, a: Pinocchio's names). out: as for idm."""
    def simulate(self, duration: float, q0: Optional[ArrayLike] = None, qd0: Optional[ArrayLike] = None, torque: Torque = None, dt: Optional[float] = None, rtol: float = 1e-8, atol: float = 1e-10, output_dt: float = 0.01, coulomb_smoothing: Optional[float] = None, max_steps: int = 5_000_000) -> Dict[str, Any]:
        """Simulate in the actuated coordinates from (q0, qd0) (rad, m; rad/s, m/s; default: the
        tracker's q_a, zeros) over [0, duration] (s); the passive joints are re-solved at every
        evaluation. Returns a dict of arrays: t (M,) s, q, qd, qdd, tau (M, nq) over the
        actuated joints, energy (M,) J, closure_residual (M,) and the passive joints' q<j> (M,).
        torque, dt, rtol, atol, output_dt, max_steps as for Robot.simulate; Ctrl-C stops the
        run."""

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

class View:
    """The page of ``robot.view()``: one self-contained HTML file (three.js embedded)."""
    html: str
    """The HTML text."""
    warnings: List[str]
    """What was drawn differently from the request (loops left open, meshes not found)."""
    def save(self, path: Union[str, PathLike]) -> None:
        """Write the page (all or nothing: a temporary file renamed into place)."""
    def _repr_html_(self) -> str: ...

class Generated:
    """A generated customized model."""
    name: str
    code: str
    multiplications: int
    additions: int
    functions: int

# Identification (robodyn identify): docs/python.md, docs/models/identification.md

Log = Union[str, PathLike, Dict[str, ArrayLike], Any]
"""A CSV path, a dict of 1-D arrays named as the CSV's columns (t, q<j>, tau<j> or i<j>, optionally
qd<j>, qdd<j>), or a pandas DataFrame with those columns."""

@overload
def identify(robot: Union[Robot, str, PathLike], logs: Union[Log, Sequence[Log]], *, estimate_gains: Literal[True], reference: Union[Log, Sequence[Log]], known_payload: Optional[Tuple[int, Sequence[float]]] = None, **options: Any) -> GainIdentification: ...
@overload
def identify(robot: Union[Robot, str, PathLike], logs: Union[Log, Sequence[Log]], *, payload: int, before: Optional[Union[Log, Sequence[Log]]] = None, **options: Any) -> PayloadIdentification: ...
@overload
def identify(robot: Union[Robot, str, PathLike], logs: Union[Log, Sequence[Log]], **options: Any) -> Identification: ...
def identify(robot: Union[Robot, str, PathLike], logs: Union[Log, Sequence[Log]], **options: Any) -> Any:
    """Identify the base parameters (friction, rotor inertias, offsets, drive parameters of a
    transmission) of ``robot`` from one log or a list of logs of it (the CLI's repeated ``--data``):
    the same numbers as ``robodyn identify``. Options (the library's identification Options, the
    CLI's flags): estimator ("ols", "wls", "iv"), consistent, standard (compute consistent standard
    parameters for ``robot()``/``write_robot``), rotor, friction, offsets, joint_drives, seed, essential,
    essential_max_std, essential_tolerance, bandwidth, cutoff, filter_order, decimation, border,
    validation ((from, to) fractions or None; default (0.8, 1.0)), use_log_derivatives, gains,
    min_speed, coulomb_band, iv_iterations, iv_bandwidth. An unknown option raises InputError.

    Drive gains (``robodyn identify --estimate-gains``): ``estimate_gains=True`` with ``logs`` of
    motor currents (``i<j>`` columns) and ``reference``, logs fixing the scale: joint torques
    (``tau<j>``), or currents carrying ``known_payload=(link, [XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ,
    M])``; returns a ``GainIdentification``. Payload (``--payload LINK``): ``payload=LINK`` with
    ``logs`` of the robot carrying it, the robot's parameters those of ``robot``, or identified too
    from ``before``, logs without the payload; returns a ``PayloadIdentification``. Neither takes
    gains, consistent, standard or essential (InputError)."""

def ident_statistics(robot: Union[Robot, str, PathLike], log: Log, **options: Any) -> IdentStatistics:
    """The sufficient statistics of one log (options as ``identify``): picklable, merged by
    ``identify_from_statistics`` into the numbers of ``identify`` of all the logs (map-reduce)."""

def identify_from_statistics(robot: Union[Robot, str, PathLike], statistics: Sequence[IdentStatistics], **options: Any) -> Identification:
    """Identify from merged statistics (of this robot, computed with the same row-shaping options:
    checked, InputError otherwise). IDIM-IV needs the logs themselves (InputError)."""

def excite(
    robot: Union[Robot, str, PathLike],
    period: float,
    harmonics: int,
    *,
    start: Optional[Union[float, ArrayLike]] = None,
    q_min: Optional[Union[float, ArrayLike]] = None,
    q_max: Optional[Union[float, ArrayLike]] = None,
    qd_max: Optional[Union[float, ArrayLike]] = None,
    qdd_max: Optional[Union[float, ArrayLike]] = None,
    tau_max: Optional[Union[float, ArrayLike]] = None,
    samples: int = 100,
    iterations: int = 1500,
    restarts: int = 20,
    seed: int = 1,
    rotor: str = "actuated",
    friction: bool = True,
    offsets: bool = False,
    rate: float = 200.0,
    periods: int = 1,
) -> Dict[str, Any]:
    """Design an exciting trajectory (the CLI's ``robodyn excite``, the same numbers): a finite
    Fourier series per actuated joint, at rest at t = 0 and T, minimizing the condition number of
    the base-parameter observation matrix under the limits (one number or one per joint; default
    the robot file's ``limits``; velocity and acceleration limits required). Returns a dict:
    ``t`` (M,), ``q``, ``qd``, ``qdd`` (M, nq) sampled at ``rate`` over ``periods`` periods (the
    CLI's CSV rows), ``condition_number``, ``initial_condition_number``, ``binding`` ((what,
    joint)), ``peaks`` (nq, 4: largest |q - start|, |qd|, |qdd|, |tau|), ``joints``,
    ``evaluations``."""

class IdentStatisticsBuilder:
    """The statistics of many logs of one robot with one set of options, the parameter model built
    once: ``builder(log)`` gives ``ident_statistics(robot, log, **options)``. Not picklable: make
    one per worker (``ident_statistics`` keeps one per robot and options in each process)."""
    def __init__(self, robot: Union[Robot, str, PathLike], **options: Any) -> None: ...
    def __call__(self, log: Log) -> IdentStatistics:
        """The statistics of one log."""

class IdentStatistics:
    """Per joint, the triangular factor of [W y] of the fit and validation rows of one or more logs,
    with the robot's fingerprint and the options that shaped the rows. Picklable (as JSON)."""
    def __init__(self, json: str) -> None:
        """Statistics from their JSON text (``to_json``, ``robodyn identify --partial``)."""
    def to_json(self) -> str:
        """The JSON text (``robodyn identify --merge`` reads it)."""
    def merge(self, other: IdentStatistics) -> IdentStatistics:
        """These statistics with ``other``'s rows (same robot and row options)."""
    rows: int
    """Rows of the fit (all joints)."""
    logs: List[str]
    """The logs' names."""

class GainIdentification:
    """The result of ``identify(..., estimate_gains=True, reference=...)``: drive gains (torque
    per unit of current) and the parameters identified with them, as the CLI's JSON report."""
    report: Dict[str, Any]
    """The JSON report of ``robodyn identify --estimate-gains --format json``."""
    gains: List[Dict[str, Any]]
    """joint, name, value, std: one per motor."""
    gain_values: Array
    gain_std: Array
    parameters: List[Dict[str, Any]]
    """name, equation, value, std."""
    values: Array
    std: Array
    reference: str
    """What fixed the scale, in words."""
    condition_number: float
    residual_rms: float

class PayloadIdentification:
    """The result of ``identify(..., payload=LINK)``: the payload's standard parameters XX, XY, XZ,
    YY, YZ, ZZ (about O_link), MX, MY, MZ, M in R_link, those the logs determine."""
    report: Dict[str, Any]
    """The JSON report of ``robodyn identify --payload LINK --format json``."""
    payload: List[Dict[str, Any]]
    """name, value, std (None where not determined on its own)."""
    values: Array
    """The 10 values (NaN where not determined)."""
    std: Array
    names: List[str]
    others: List[Dict[str, Any]]
    """The other unknowns: offsets, or the robot's parameters (before/after)."""
    link: int
    rank: int
    """Combinations of the 10 the logs determine."""
    structural_rank: int
    """Combinations that change the torques at all."""
    undetermined: List[str]
    relative_error: float
    condition_number: float

class Identification:
    """The result of ``identify``."""
    report: Dict[str, Any]
    """The JSON report of ``robodyn identify --format json``."""
    parameters: List[Dict[str, Any]]
    """name, unit, equation, value, std, relative_std (%, None when infinite)."""
    names: List[str]
    values: Array
    std: Array
    relative_std: Array
    estimator: str
    condition_number: float
    """Condition number of W with unit-norm columns."""
    condition_number_unscaled: float
    relative_error: float
    """||Y - W X|| / ||Y|| over the fit rows."""
    per_joint: List[Dict[str, Any]]
    """joint, name, rows, rms, relative_error, sigma (the WLS weight is 1/sigma)."""
    validation: Optional[Dict[str, Any]]
    """The validation segment's errors (decimated and raw torques), None without a segment."""
    warnings: List[Dict[str, Any]]
    """kind, parameters, message."""
    notes: List[str]
    predictions: Union[Dict[str, Any], List[Dict[str, Any]], None]
    """The model's torques at every sample of the log (between the processing's borders): a dict
    ``t`` (M,), ``tau`` (M, N), ``joints`` (frame numbers); a list of them when the logs were a
    list; None from statistics. ``robodyn identify --predictions FILE``."""
    def validation_prediction(self) -> Tuple[Array, Array, Array]:
        """(t (M,), measured (M, N), predicted (M, N)) torques of the validation segment's decimated
        samples, for a plot."""
    def text(self) -> str:
        """The report as ``robodyn identify`` prints it."""
    def to_pandas(self) -> Any:
        """The parameters as a pandas DataFrame (ImportError without pandas)."""
    def robot(self) -> Robot:
        """The identified robot (consistent standard parameters; identify with standard=True or
        consistent=True)."""
    def write_robot(self, path: Union[str, PathLike]) -> None:
        """Write the identified robot (.toml or .par)."""
