"""robodyn from Python, step by step (run from the repository root:
`python crates/robodyn-py/examples/quickstart.py`)."""

# %% A serial robot from URDF: vectors hold the movable joints, in robot.joint_names order
import numpy as np

import robodyn

robot = robodyn.load("robots/rx90.urdf")
print(robot, robot.joint_names)
n = robot.nq
q, qd, qdd = np.full(n, 0.1), np.full(n, 0.2), np.full(n, 0.3)
tau = robot.idm(q, qd, qdd)  # N m, Newton–Euler (10.3–10.12)
A = robot.inertia(q)  # A(q), composite links
print("tau =", tau)
print("A qdd + H - tau =", np.abs(A @ qdd + robot.h(q, qd) - tau).max())
print("ddm(idm) - qdd =", np.abs(robot.ddm(q, qd, tau, method="aba") - qdd).max())

# %% N states at once: 2-D arrays, one row per state, computed over all cores (GIL released)
rng = np.random.default_rng(0)
Q, QD, QDD = (rng.uniform(-1, 1, (100_000, n)) for _ in range(3))
TAU = robot.idm(Q, QD, QDD)
print("batch:", TAU.shape)

# %% Where the frames are: 0T_j of every frame
T = robot.forward_kinematics(q)
print("last frame origin:", T[-1, :3, 3], robot.description_frame_names[-1])

# %% Kinematics by frame name (robot.frame_names): placement, Jacobian, centre of mass, IK
tool = robot.description_frame_names[-1]
print("0T_tool =", robot.placement(q, tool))
print("J (local_world_aligned) =", robot.jacobian(q, tool, "local_world_aligned"))
print("com =", robot.com(q), "mass =", robot.mass)
sols = robot.ik(tool, robot.placement(q, tool))
print("IK:", len(sols["q"]), "solutions,", sols["within_limits"].sum(), "within the limits")

# %% Symbols: change a value, save the robot
sr400 = robodyn.load("robots/sr400.toml")
print(sorted(sr400.symbols)[:5])

# %% A closed chain: vectors hold the actuated joints; passive joints by loop closure on the
# assembly branch (the tracker is kept by the ClosedChain object)
chain = robodyn.ClosedChain(sr400)
qa = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 1.6])
print("actuated:", chain.joint_names)
print("Gamma_cl =", chain.idm(qa, np.zeros(6), np.zeros(6)))
print("q_p =", chain.solve_loops(qa))

# %% Base parameters (Table 10.2 for the SR400: 42 without friction)
bp = sr400.base_parameters(method="symbolic", friction=False)
print(len(bp), "base parameters; first:", bp.names[0], "=", bp.equations[0])

# %% Regressor with base columns: Phi_b K_b = Gamma (identification)
phi_b = robot.regressor(Q[:100], QD[:100], QDD[:100], columns="base")
K_b = np.array(robot.base_parameters().values)
print("|Phi_b K_b - tau| =", np.abs(phi_b @ K_b - TAU[:100].reshape(-1)).max())

# %% Generated code and its operation counts
gen = robot.generate(model="idm", lang="python", numeric=True)
print(gen.name, gen.multiplications, "multiplications,", gen.additions, "additions")

# %% Simulation: falling under gravity with a PD-like torque from a callback
traj = robot.simulate(1.0, q0=q, torque=lambda t, q, qd: -20.0 * qd, output_dt=0.1)
print("t =", traj["t"][-1], "q =", traj["q"][-1], "energy =", traj["energy"][-1])

# %% Errors are exceptions under robodyn.Error
try:
    robot.idm(np.zeros(n + 1))
except robodyn.DimensionError as e:
    print("DimensionError:", e)
