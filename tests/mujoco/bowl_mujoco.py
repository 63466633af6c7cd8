#!/usr/bin/env python3
"""An independent rigid-body reference for `bowl predict --model bowl` with a wall (issue 30):
MuJoCo (a physics engine nobody here wrote) drives a bowl about the vertical (precession w1)
and about its own axis (spin w2), tilted by th (paper Eq. 2's angle between the axes), on a rod
offset L, and drops nothing: a sphere starts at rest relative to the bowl on its bottom at
radius ri, azimuth beta from the downhill direction (as the model's releases), and is followed
until its centre passes the lip's radius or the horizon.

The bowl is built from primitives (MuJoCo collides meshes by their convex hulls, which would
fill the bowl): a cylinder for the bottom (top face at z = 0, radius R with no wall) and N
box staves for the wall, each a plane face on the cone at alpha from the bottom plane, from the
bottom up to the lip at R + H cot alpha (a sharp corner and a sharp lip edge). The bowl's joints
are set to the prescribed angles and speeds before every step, so the drive is exact.

Contact: elliptic friction cones, sliding mu_s, rolling friction mu_r a (MuJoCo's rolling
coefficient is a length), no torsional friction (the model has none), a stiff critically damped
contact (solref 0.0005 1: restitution near 0). The regime of each step: the centre more than
0.1 mm off the surface = fly; a contact point slipping faster than 1 mm/s against the bowl =
slide; otherwise roll.

Usage: bowl_mujoco.py W1 W2 TH_DEG R RI A MU_R MU_S ALPHA_DEG H L HORIZON BETA_DEG [BETA_DEG ...]
prints one line per azimuth: beta_deg T_s (or 'held' if still inside at the horizon)
roll_share slide_share fly_share
"""
import sys

import mujoco
import numpy as np

STAVES = 96
DT = 1e-5
SLIP_M_S = 1e-3
GAP_M = 1e-4


def model_xml(th, rim, a, mu_r, mu_s, alpha, h, rod):
    lip = rim + (h / np.tan(alpha) if h > 0 else 0.0)
    staves = []
    if h > 0:
        thick = 0.004
        slant = h / np.sin(alpha) + thick  # runs a little below the bottom's face
        width = 2.0 * (lip + thick) * np.tan(np.pi / STAVES) * 1.2
        for i in range(STAVES):
            ph = 2.0 * np.pi * i / STAVES
            er = np.array([np.cos(ph), np.sin(ph), 0.0])
            ep = np.array([-np.sin(ph), np.cos(ph), 0.0])
            ez = np.array([0.0, 0.0, 1.0])
            d = np.cos(alpha) * er + np.sin(alpha) * ez
            n_out = np.sin(alpha) * er - np.cos(alpha) * ez
            top = lip * er + h * ez
            mid = top - 0.5 * slant * d + 0.5 * thick * n_out
            staves.append(
                f'<geom type="box" size="{thick/2} {width/2} {slant/2}" pos="{mid[0]} {mid[1]} {mid[2]}" '
                f'xyaxes="{n_out[0]} {n_out[1]} {n_out[2]} {ep[0]} {ep[1]} {ep[2]}"/>'
            )
    bottom_r = rim if h <= 0 else rim + 0.01
    return f"""
<mujoco>
  <compiler angle="radian"/>
  <option timestep="{DT}" gravity="0 0 -9.81" cone="elliptic" integrator="implicitfast"/>
  <default>
    <geom condim="6" friction="{mu_s} 0 {mu_r * a}" solref="0.0005 1" solimp="0.99 0.999 0.0001"/>
  </default>
  <worldbody>
    <body name="carrier">
      <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
      <joint name="precession" type="hinge" axis="0 0 1"/>
      <body name="bowl" pos="{-rod} 0 0" euler="0 {-th} 0">
        <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
        <joint name="spin" type="hinge" axis="0 0 1"/>
        <geom type="cylinder" size="{bottom_r} 0.005" pos="0 0 -0.005"/>
        {''.join(staves)}
      </body>
    </body>
    <body name="ball">
      <freejoint/>
      <geom name="ball" type="sphere" size="{a}" mass="0.001"/>
    </body>
  </worldbody>
</mujoco>"""


def rz(x):
    c, s = np.cos(x), np.sin(x)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(x):
    c, s = np.cos(x), np.sin(x)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def surface_gap(q, rim, a, alpha, h, lip):
    """The centre's distance to the bowl's surface less a (bottom, cone, lip's edge), with the
    surface's unit normal towards the centre, in the bowl frame."""
    rho = np.hypot(q[0], q[1])
    er = np.array([q[0], q[1], 0.0]) / max(rho, 1e-15)
    best = (q[2] - a, np.array([0.0, 0.0, 1.0]))
    if h > 0:
        sa, ca = np.sin(alpha), np.cos(alpha)
        along = (rho - rim) * ca + q[2] * sa
        if along <= h / sa:
            dc = -(rho - rim) * sa + q[2] * ca - a
            if dc < best[0]:
                best = (dc, -sa * er + ca * np.array([0.0, 0.0, 1.0]))
        else:
            e = np.array([rho - lip, q[2] - h])
            de = np.hypot(*e) - a
            if de < best[0]:
                u = e / np.hypot(*e)
                best = (de, u[0] * er + u[1] * np.array([0.0, 0.0, 1.0]))
    return best


def run(w1, w2, th, rim, ri, a, mu_r, mu_s, alpha, h, rod, horizon, beta):
    m = mujoco.MjModel.from_xml_string(model_xml(th, rim, a, mu_r, mu_s, alpha, h, rod))
    d = mujoco.MjData(m)
    lip = rim + (h / np.tan(alpha) if h > 0 else 0.0)
    ball = m.body("ball").id
    ez = np.array([0.0, 0.0, 1.0])

    def pose(t):
        rot = rz(w1 * t) @ ry(-th) @ rz(w2 * t)
        o = -rod * rz(w1 * t)[:, 0]
        n = rot[:, 2]
        w = w1 * ez + w2 * n
        odot = np.cross(w1 * ez, o)
        return rot, o, odot, w

    # At rest relative to the bowl on its bottom at ri, azimuth beta from downhill.
    rot, o, odot, w = pose(0.0)
    q0 = np.array([-ri * np.cos(beta), -ri * np.sin(beta), a])
    x0 = o + rot @ q0
    v0 = odot + np.cross(w, x0 - o)
    jq = 2  # the free joint after the two hinges
    d.qpos[jq:jq + 3] = x0
    d.qpos[jq + 3:jq + 7] = [1.0, 0.0, 0.0, 0.0]
    d.qvel[2:5] = v0
    d.qvel[5:8] = w  # free joint's angular velocity is in the body frame: identity orientation
    t = 0.0
    shares = {"roll": 0.0, "slide": 0.0, "fly": 0.0}
    while t < horizon:
        d.qpos[0], d.qpos[1] = w1 * t, w2 * t
        d.qvel[0], d.qvel[1] = w1, w2
        d.time = t
        mujoco.mj_step(m, d)
        t += DT
        rot, o, odot, w = pose(t)
        x = d.xpos[ball].copy()
        q = rot.T @ (x - o)
        if np.hypot(q[0], q[1]) > lip:
            return t, shares
        # Touching: the centre within 0.1 mm of the bowl's surface offset by a (measured here
        # on the true cone; the staves' facets are within 0.05 mm of it), the normal there.
        gap, normal_b = surface_gap(q, rim, a, alpha, h, lip)
        if gap > GAP_M:
            shares["fly"] += DT
            continue
        normal = rot @ normal_b
        p = x - a * normal
        xmat = d.xmat[ball].reshape(3, 3)
        omega = xmat @ d.qvel[5:8]
        v = d.qvel[2:5]
        slip = v + np.cross(omega, p - x) - (odot + np.cross(w, p - o))
        slip -= (slip @ normal) * normal
        shares["slide" if np.linalg.norm(slip) > SLIP_M_S else "roll"] += DT
    return None, shares


def main():
    v = [float(s) for s in sys.argv[1:]]
    w1, w2, th, rim, ri, a, mu_r, mu_s, alpha, h, rod, horizon = v[:12]
    for beta in v[12:]:
        t, sh = run(w1, w2, np.radians(th), rim, ri, a, mu_r, mu_s, np.radians(alpha), h, rod,
                    horizon, np.radians(beta))
        total = sum(sh.values()) or 1.0
        print(beta, "held" if t is None else f"{t:.6f}",
              " ".join(f"{sh[k] / total:.4f}" for k in ("roll", "slide", "fly")), flush=True)


if __name__ == "__main__":
    main()
