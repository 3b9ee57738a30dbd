"""robodyn: dynamic models of robots with complex structure (trees and closed kinematic chains)
in the Khalil-Kleinfinger notation, on NumPy arrays.

    import robodyn
    robot = robodyn.load("robots/rx90.urdf")
    tau = robot.idm(q, qd, qdd)        # one state: 1-D arrays; N states: (N, nq) arrays

Every model function takes one state (1-D arrays of length ``robot.nq``) or N states (2-D arrays,
one row per state, evaluated in Rust over all cores with the GIL released).
"""

from ._robodyn import (
    BaseParameters,
    BranchLost,
    ClosedChain,
    DimensionError,
    Error,
    GainIdentification,
    Generated,
    IdentStatistics,
    IdentStatisticsBuilder,
    Identification,
    InputError,
    LoopClosureError,
    NotFiniteError,
    NumericalError,
    PayloadIdentification,
    PhysicalParameterError,
    Robot,
    RobotFileError,
    RobotFileWarning,
    SingularConfiguration,
    SingularityWarning,
    View,
    __version__,
    base_parameters,
    excite,
    ident_statistics,
    identify,
    identify_from_statistics,
    load,
)

__all__ = [
    "BaseParameters",
    "BranchLost",
    "ClosedChain",
    "DimensionError",
    "Error",
    "GainIdentification",
    "Generated",
    "IdentStatistics",
    "IdentStatisticsBuilder",
    "Identification",
    "InputError",
    "LoopClosureError",
    "NotFiniteError",
    "NumericalError",
    "PayloadIdentification",
    "PhysicalParameterError",
    "Robot",
    "RobotFileError",
    "RobotFileWarning",
    "SingularConfiguration",
    "SingularityWarning",
    "View",
    "__version__",
    "base_parameters",
    "excite",
    "ident_statistics",
    "identify",
    "identify_from_statistics",
    "load",
]
