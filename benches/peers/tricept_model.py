"""The exact measurement model of the Tricept's UP limb, written from the
project's documented conventions (docs/conventions.md), in numpy, with no
code of tricept's: what a user would write to identify the machine with a
general least-squares library.

Base joints B_i = b (cos a_i, sin a_i, 0) + db_i, platform joints
A_i = a (cos a_i, sin a_i, 0) + da_i (platform frame); the UP limb's U
joint at the base origin, x-first: R = Rx(phi) Ry(theta), r = q4 R e_z.
A pose is commanded by leg lengths q_i; the actual leg is q_i + dq_i, so
the joints (phi, theta, q4) solve |r + R A_i - B_i| = q_i + dq_i (forward
kinematics, Newton on all poses at once). The readings are the joints plus
the sensors' zero offsets.

The paper's 15 parameters (its frame conventions: dzB1 = dzB2 = dzA_i = 0,
dxB1 = dxB2) in the order of tricept's `paper15`:
dxB1, dyB1, dyB2, dxB3, dyB3, dzB3, dxA1, dyA1, dxA2, dyA2, dxA3, dyA3,
dq1, dq2, dq3.
"""

import json

import numpy as np

NAMES = ["dxB1", "dyB1", "dyB2", "dxB3", "dyB3", "dzB3", "dxA1", "dyA1",
         "dxA2", "dyA2", "dxA3", "dyA3", "dq1", "dq2", "dq3"]


def paper15_map():
    """E (21 x 15): the full errors [db1 db2 db3 (x, y, z each), da1 da2 da3
    (x, y, z), dq1 dq2 dq3] of the 15 parameters."""
    full = [f"d{c}B{i}" for i in (1, 2, 3) for c in "xyz"] + \
           [f"d{c}A{i}" for i in (1, 2, 3) for c in "xyz"] + ["dq1", "dq2", "dq3"]
    E = np.zeros((21, 15))
    for k, name in enumerate(NAMES):
        E[full.index(name), k] = 1.0
    E[full.index("dxB2"), NAMES.index("dxB1")] = 1.0
    return E


class Machine:
    """The nominal machine of a tricept machine description (circular
    placement, ideal x-first U joint)."""

    def __init__(self, description_path):
        d = json.load(open(description_path))
        p = d["placement"]["circular"]
        a = np.radians(p["joint_angles_deg"])
        ring = np.stack([np.cos(a), np.sin(a), np.zeros(3)], axis=1)
        self.B = p["base_radius_mm"] * ring
        self.A = p["platform_radius_mm"] * ring
        if d.get("up_limb", {}).get("axis_order", "x-first") != "x-first":
            raise ValueError("this peer implements the x-first U joint only")
        self.E = paper15_map()

    def actual(self, params):
        """Base joints, platform joints and leg errors of the 15 parameters."""
        e = self.E @ params
        return self.B + e[0:9].reshape(3, 3), self.A + e[9:18].reshape(3, 3), e[18:21]


def rotation(phi, theta):
    """R = Rx(phi) Ry(theta) and its derivatives, each (n, 3, 3)."""
    sp, cp, st, ct = np.sin(phi), np.cos(phi), np.sin(theta), np.cos(theta)
    z, o = np.zeros_like(phi), np.ones_like(phi)
    rx = np.stack([o, z, z, z, cp, -sp, z, sp, cp], -1).reshape(-1, 3, 3)
    drx = np.stack([z, z, z, z, -sp, -cp, z, cp, -sp], -1).reshape(-1, 3, 3)
    ry = np.stack([ct, z, st, z, o, z, -st, z, ct], -1).reshape(-1, 3, 3)
    dry = np.stack([-st, z, ct, z, z, z, -ct, z, -st], -1).reshape(-1, 3, 3)
    return rx @ ry, drx @ ry, rx @ dry


def legs(joints, B, A):
    """Leg vectors L_i = r + R A_i - B_i (n, 3 legs, 3) and the derivatives
    of |L_i| with respect to the joints (n, 3, 3) and of the pieces needed
    for the parameters: the unit vectors u_i and R."""
    phi, theta, q4 = joints.T
    R, dRp, dRt = rotation(phi, theta)
    ez = np.array([0.0, 0.0, 1.0])
    r = q4[:, None] * (R @ ez)
    L = r[:, None, :] + np.einsum("njk,ik->nij", R, A) - B[None]
    length = np.linalg.norm(L, axis=2)
    u = L / length[..., None]
    dL = [q4[:, None, None] * (dRp @ ez)[:, None, :] + np.einsum("njk,ik->nij", dRp, A),
          q4[:, None, None] * (dRt @ ez)[:, None, :] + np.einsum("njk,ik->nij", dRt, A),
          np.broadcast_to((R @ ez)[:, None, :], L.shape)]
    J1 = np.stack([np.einsum("nij,nij->ni", u, d) for d in dL], axis=2)
    return length, u, R, J1


def forward(commands, params, machine, seeds=None, tol=1e-11, max_iter=50):
    """Joints (phi, theta, q4) of every pose (n, 3) by Newton, from `seeds`
    (previous solutions) or from a level platform at the mean leg length."""
    B, A, dq = machine.actual(params)
    target = commands + dq
    if seeds is None:
        seeds = np.zeros((len(commands), 3))
        seeds[:, 2] = target.mean(axis=1) * 0.95
    j = seeds.copy()
    for _ in range(max_iter):
        length, _, _, J1 = legs(j, B, A)
        f = length - target
        if np.max(np.abs(f)) < tol:
            return j
        j = j - np.linalg.solve(J1, f[..., None])[..., 0]
    raise RuntimeError("forward kinematics did not converge")


def jacobian(joints, params, machine):
    """d joints / d params (n, 3, 15) by the implicit function theorem:
    -(dF/dj)^-1 dF/dp with F_i = |L_i| - (q_i + dq_i)."""
    B, A, _ = machine.actual(params)
    _, u, R, J1 = legs(joints, B, A)
    n = len(joints)
    dF = np.zeros((n, 3, 21))
    for i in range(3):
        dF[:, i, 3 * i:3 * i + 3] = -u[:, i, :]                           # d/d b_i
        dF[:, i, 9 + 3 * i:12 + 3 * i] = np.einsum("nk,nkl->nl", u[:, i, :], R)  # d/d a_i
        dF[:, i, 18 + i] = -1.0                                            # d/d dq_i
    return -np.linalg.solve(J1, dF @ machine.E)


def read_csv(path):
    """Commands (n, 3) and readings (n, 3) of a tricept measured-data CSV."""
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                header = [h.strip() for h in line.split(",")]
                break
        data = np.loadtxt(f, delimiter=",", comments="#", ndmin=2)
    col = [header.index(c) for c in ("q1", "q2", "q3", "phi", "theta", "s")]
    return data[:, col[:3]], data[:, col[3:]]
