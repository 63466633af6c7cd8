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
bottom up to the lip at R + H cot alpha (a sharp corner and a sharp lip edge). With a fillet of radius F (> a) the corner is
FILLET_CHORDS bands of staves on the arc's chords (tangent to the bottom at R - F tan(alpha/2)
and to the cone), then the cone's staves up to the lip. The bowl's joints
are set to the prescribed angles and speeds before every step, so the drive is exact.

Contact: elliptic friction cones, sliding mu_s, rolling friction mu_r a (MuJoCo's rolling
coefficient is a length), no torsional friction (the model has none), a stiff critically damped
contact (solref 0.0005 1; its impact still returns e 0.13-0.15 of the normal speed: see
impact_mujoco.py). The regime of each step: the centre more than 0.1 mm off the surface = fly;
else slide if MuJoCo's last contact force is at the friction cone (|f_t| >= 0.8 mu_s f_n),
roll if inside it (see the loop for why not the slip speed).

Usage: bowl_mujoco.py [--trace DT_S] [--dampratio D] [--torque] [--friction-tc S]
                      W1 W2 TH_DEG R RI A MU_R MU_S ALPHA_DEG H L HORIZON F BETA_DEG [BETA_DEG ...]
prints one line per azimuth: beta_deg T_s (or 'held' if still inside at the horizon)
roll_share slide_share fly_share how (flight: its centre passed the lip while off the surface;
contact: while touching; held). --trace prints each release's path every DT_S seconds (and
at each change of mode) first: t, rho and z in the bowl frame, the speed relative to the bowl
(its radial and axial parts), the gap to the surface, the mode; --dampratio the contact's
damping ratio (sweep.py's for a restitution; default 1); --torque the rolling resistance as a
torque (run's `torque`, as sweep.py runs it); --friction-tc the friction's own time constant
(run's `friction_tc`); --impact-vn V the rolling resistance (with --torque) only while the
contact's normal speed is at most V m/s, not in impacts (run's `impact_vn`); --staves N the
wall's staves (default 96: a finer wall checks the faceting); --dt S the timestep.
"""
import sys

import mujoco
import numpy as np

STAVES = 96
FILLET_CHORDS = 16
DT = 1e-5
GAP_M = 1e-4
CONE = 0.8
# With the rolling resistance as a torque (run's `torque`) the sliding friction alone fills the
# cone: a slide reads 0.99-1.0, and a granule that sticks near the cone (rolling needs 0.8-0.95
# of mu_s N, e.g. 63 deg tilt, mu_s 0.53) read 0.8 as a slide, lost its rolling resistance and
# left 1 % early; 0.95 and 0.99 give the same T (to 0.1 %) and regime.
CONE_TORQUE = 0.95


def ring(staves, p0, p1, thick, extend=1.2):
    """A ring of STAVES boxes whose inner faces are the band of the surface of revolution swept
    by the meridian's chord p0 -> p1 ((rho, z) points), the box behind the face."""
    (r0, z0), (r1, z1) = p0, p1
    length = np.hypot(r1 - r0, z1 - z0)
    dr, dz = (r1 - r0) / length, (z1 - z0) / length
    rmax = max(r0, r1)
    width = 2.0 * (rmax + thick) * np.tan(np.pi / STAVES) * 1.2
    for i in range(STAVES):
        ph = 2.0 * np.pi * i / STAVES
        er = np.array([np.cos(ph), np.sin(ph), 0.0])
        ep = np.array([-np.sin(ph), np.cos(ph), 0.0])
        ez = np.array([0.0, 0.0, 1.0])
        d = dr * er + dz * ez
        n_out = dz * er - dr * ez
        mid = 0.5 * (r0 + r1) * er + 0.5 * (z0 + z1) * ez + 0.5 * thick * n_out
        staves.append(
            f'<geom type="box" size="{thick/2} {width/2} {extend * length/2}" '
            f'pos="{mid[0]} {mid[1]} {mid[2]}" '
            f'xyaxes="{n_out[0]} {n_out[1]} {n_out[2]} {ep[0]} {ep[1]} {ep[2]}"/>'
        )


def model_xml(th, rim, a, mu_r, mu_s, alpha, h, rod, fillet=0.0, dampratio=1.0, torque=False,
              friction_tc=None):
    lip = rim + (h / np.tan(alpha) if h > 0 else 0.0)
    staves = []
    if h > 0 and fillet > 0:
        # The fillet (radius F, tangent to the bottom at rho_b = R - F tan(alpha/2) and to the
        # cone) as FILLET_CHORDS bands of chords (each within F (1 - cos(alpha/2K)) of the arc:
        # 5 um at F 5 mm), then the cone from the fillet's end to the lip.
        rho_b = rim - fillet * np.tan(alpha / 2)
        arc = [(rho_b + fillet * np.sin(t), fillet * (1 - np.cos(t)))
               for t in np.linspace(0.0, alpha, FILLET_CHORDS + 1)]
        for p0, p1 in zip(arc[:-1], arc[1:]):
            ring(staves, p0, p1, 0.004)
        ring(staves, arc[-1], (lip, h), 0.004, extend=1.0)
    elif h > 0:
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
    # MuJoCo's rolling friction shares the elliptic cone with the sliding friction (see run's
    # `torque`); with `torque` the contact has sliding friction alone (condim 3).
    friction = f'condim="3" friction="{mu_s} 0 0"' if torque else \
        f'condim="6" friction="{mu_s} 0 {mu_r * a}"'
    ball = f'<geom name="ball" type="sphere" size="{a}" mass="0.001"/>'
    pairs = ""
    if friction_tc:
        # The friction's own time constant (solreffriction, which only an explicit contact pair
        # takes): with the normal's (0.5 ms) the friction is still relaxing towards a stick
        # when an impact with e 0.5 is over, and a sticking impact gets half to 70 % of
        # Routh's tangential impulse at any timestep, stiffness, impratio or noslip (docs/model.md
        # §10, the sweep's scene 8); at 0.1 ms it gets Routh's. Every bowl geom is paired with
        # the ball, whose own collisions are off (no contact twice).
        names = [f"w{i}" for i in range(len(staves) + 1)]
        staves = [g.replace("<geom ", f'<geom name="{n}" ', 1)
                  for g, n in zip(staves, names[1:])]
        ball = ball.replace("<geom ", '<geom contype="0" conaffinity="0" ', 1)
        cond = "3" if torque else "6"
        fr = f"{mu_s} {mu_s} 0 0 0" if torque else f"{mu_s} {mu_s} 0 {mu_r * a} {mu_r * a}"
        pairs = "<contact>" + "".join(
            f'<pair geom1="{n}" geom2="ball" condim="{cond}" friction="{fr}" '
            f'solref="0.0005 {dampratio}" solimp="0.99 0.999 0.0001" '
            f'solreffriction="{friction_tc} 1"/>' for n in names) + "</contact>"
    bottom_name = ' name="w0"' if friction_tc else ""
    return f"""
<mujoco>
  <compiler angle="radian"/>
  <option timestep="{DT}" gravity="0 0 -9.81" cone="elliptic" integrator="implicitfast"/>
  <default>
    <geom {friction} solref="0.0005 {dampratio}" solimp="0.99 0.999 0.0001"/>
  </default>
  <worldbody>
    <body name="carrier">
      <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
      <joint name="precession" type="hinge" axis="0 0 1"/>
      <body name="bowl" pos="{-rod} 0 0" euler="0 {-th} 0">
        <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
        <joint name="spin" type="hinge" axis="0 0 1"/>
        <geom{bottom_name} type="cylinder" size="{bottom_r} 0.005" pos="0 0 -0.005"/>
        {''.join(staves)}
      </body>
    </body>
    <body name="ball">
      <freejoint/>
      {ball}
    </body>
  </worldbody>
  {pairs}
</mujoco>"""


def rz(x):
    c, s = np.cos(x), np.sin(x)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(x):
    c, s = np.cos(x), np.sin(x)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def surface_gap(q, rim, a, alpha, h, lip, fillet):
    """The centre's distance to the bowl's surface less a (bottom, fillet, cone, lip's edge):
    the least over the pieces whose nearest point lies on them, in the bowl frame."""
    rho = np.hypot(q[0], q[1])
    best = q[2] - a
    if h > 0:
        sa, ca = np.sin(alpha), np.cos(alpha)
        if fillet > 0:
            rho_b = rim - fillet * np.tan(alpha / 2)
            dr, dz = rho - rho_b, q[2] - fillet
            if 0.0 <= np.arctan2(dr, -dz) <= alpha:
                best = min(best, fillet - np.hypot(dr, dz) - a)
        along = (rho - rim) * ca + q[2] * sa
        if along <= h / sa:
            best = min(best, -(rho - rim) * sa + q[2] * ca - a)
        else:
            best = min(best, np.hypot(rho - lip, q[2] - h) - a)
    return best


def run(w1, w2, th, rim, ri, a, mu_r, mu_s, alpha, h, rod, horizon, beta, fillet=0.0,
        dampratio=1.0, dt=DT, torque=False, trace=None, trace_every_s=1e-3, friction_tc=None,
        impact_vn=None):
    """dampratio: the contact's damping ratio (1: critically damped, e 0.13-0.15; sweep.py
    sets it for a restitution); dt: the timestep (a finer one checks the reference).

    torque: the rolling resistance as a torque mu_r a N against the rolling, applied while the
    contact sticks (the issue's roll mode; its slide has Coulomb friction alone), instead of
    MuJoCo's rolling friction. MuJoCo's elliptic cone bounds the sliding friction and the
    rolling torque together (|f_t/mu_s|^2 + |tau/(mu_r a)|^2 <= N^2): on a still incline a
    sliding sphere then gets less than mu_s N (38 deg, mu_s 0.21, mu_r 0.018: 2.7 % more
    acceleration than g (sin th - mu_s cos th); 0.3 % with mu_r 0) and a rolling one creeps (20
    deg, mu_r 0.046: slips 5 % of its speed, 2.4 % more than k2 g (sin th - mu_r cos th)); with
    the torque both closed forms hold to 1e-4.

    impact_vn: with `torque`, the rolling resistance only while the contact's normal speed (the
    centre's velocity relative to the bowl along the contact normal) is at most this, m/s: not
    during an impact. The torque mu_r a N with an impact's normal force (150 g in a sharp
    corner) is an angular impulse mu_r a J_n that the issue's impact (restitution and Coulomb
    friction, the model's `flight::impact`) does not have: in the held-out sweep's scene 20
    (36 deg wall, sharp corner, mu_r 0.024) it took 0.028 m/s off `a w` in the corner, the
    granule went up the wall with 0.013 m^2/s^2 less `|u|^2` than the model's, stopped 1 mm
    short of the lip where the model's passes and left 1.7-2.1 % later (docs/model.md §10,
    "Scene 20"; 0.005-0.02 m/s give the same to 0.3 %).

    trace: a list that gets a row every trace_every_s (and at every change of mode): t, the
    centre's radius from the bowl's axis rho and height z in the bowl frame, its speed relative
    to the bowl, the gap to the surface, the mode (fly, roll or slide), and the velocity's
    radial and axial components, to see where a release parts from the model's."""
    m = mujoco.MjModel.from_xml_string(model_xml(th, rim, a, mu_r, mu_s, alpha, h, rod, fillet,
                                                 dampratio, torque, friction_tc))
    m.opt.timestep = dt
    cone = CONE_TORQUE if torque else CONE
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
    bgeom = m.geom("ball").id
    force = np.zeros(6)
    sliding = False  # released at rest on the bottom: rolling until a contact says otherwise
    touching = True
    last_mode, next_row = None, 0.0
    while t < horizon:
        d.qpos[0], d.qpos[1] = w1 * t, w2 * t
        d.qvel[0], d.qvel[1] = w1, w2
        d.time = t
        mujoco.mj_step(m, d)
        t += dt
        rot, o, odot, w = pose(t)
        x = d.xpos[ball].copy()
        q = rot.T @ (x - o)
        if np.hypot(q[0], q[1]) > lip:
            return t, shares, touching
        # Flying: the centre more than 0.1 mm off the bowl's surface offset by a (the true
        # surface; the staves' facets are within 0.05 mm of it). MuJoCo's stiff contact
        # chatters in micro-hops of a few um while touching (a contact in a few % of the steps),
        # so its contact list does not say this. Touching: sliding if the last contact's
        # friction force is at the friction cone (|f_t| >= 0.8 mu_s f_n: a slide reads 0.97,
        # the cone shared with the rolling resistance), rolling if inside it. Not the slip
        # speed: the soft contact lets a rolling (sticking) granule creep at 4-10 mm/s on the
        # wall with its friction at 9-15 % of the cone.
        verdicts = []
        tq = np.zeros(3)
        for i in range(d.ncon):
            c = d.contact[i]
            if bgeom in (c.geom1, c.geom2):
                mujoco.mj_contactForce(m, d, i, force)
                if force[0] > 0.0:
                    slides = np.hypot(force[1], force[2]) >= cone * mu_s * force[0]
                    verdicts.append(slides)
                    if torque and not slides:
                        # Against the rolling: u the centre's velocity relative to the bowl
                        # along the surface, n from the contact to the centre.
                        n = x - c.pos
                        n /= np.linalg.norm(n)
                        u = d.qvel[jq:jq + 3] - odot - np.cross(w, x - o)
                        vn = np.dot(u, n)
                        u -= vn * n
                        if impact_vn is not None and abs(vn) > impact_vn:
                            continue
                        speed = np.linalg.norm(u)
                        if speed > 1e-9:
                            tq -= mu_r * a * force[0] * np.cross(n, u / speed)
        if torque:
            d.xfrc_applied[ball, 3:6] = tq
        if verdicts:
            sliding = any(verdicts)
        gap = surface_gap(q, rim, a, alpha, h, lip, fillet)
        touching = gap <= GAP_M
        if trace is not None:
            mode = "fly" if not touching else ("slide" if sliding else "roll")
            if mode != last_mode or t >= next_row:
                u = rot.T @ (d.qvel[jq:jq + 3] - odot - np.cross(w, x - o))
                rho = np.hypot(q[0], q[1])
                er = np.array([q[0], q[1], 0.0]) / rho
                trace.append((t, float(rho), float(q[2]), float(np.linalg.norm(u)), float(gap),
                              mode, float(u @ er), float(u[2])))
                last_mode, next_row = mode, t + trace_every_s
        if not touching:
            shares["fly"] += dt
            continue
        shares["slide" if sliding else "roll"] += dt
    return None, shares, touching


def main():
    args = sys.argv[1:]
    global STAVES
    every, dampratio, torque, ftc, dt, ivn = None, 1.0, False, None, DT, None
    options = ("--trace DT_S, --dampratio D, --torque, --friction-tc S, --impact-vn V, "
               "--staves N, --dt S")
    while args and args[0].startswith("--"):
        if args[0] == "--torque":
            torque, args = True, args[1:]
            continue
        if len(args) < 2:
            sys.exit(f"{args[0]} needs a value (the options: {options})")
        if args[0] == "--trace":
            every = float(args[1])
        elif args[0] == "--dampratio":
            dampratio = float(args[1])
        elif args[0] == "--friction-tc":
            ftc = float(args[1])
        elif args[0] == "--impact-vn":
            ivn = float(args[1])
        elif args[0] == "--staves":
            STAVES = int(args[1])
        elif args[0] == "--dt":
            dt = float(args[1])
        else:
            sys.exit(f"unknown option {args[0]}: the options are {options}")
        args = args[2:]
    v = [float(s) for s in args]
    w1, w2, th, rim, ri, a, mu_r, mu_s, alpha, h, rod, horizon, fillet = v[:13]
    for beta in v[13:]:
        trace = [] if every else None
        t, sh, touching = run(w1, w2, np.radians(th), rim, ri, a, mu_r, mu_s, np.radians(alpha),
                              h, rod, horizon, np.radians(beta), fillet, dampratio=dampratio,
                              dt=dt, torque=torque, trace=trace,
                              trace_every_s=every or 1e-3, friction_tc=ftc, impact_vn=ivn)
        for row in trace or []:
            print(f"  {row[0]:.5f} rho {1e3 * row[1]:.3f} mm z {1e3 * row[2]:.3f} mm "
                  f"speed {row[3]:.4f} m/s (radial {row[6]:+.4f}, up {row[7]:+.4f}) "
                  f"gap {1e3 * row[4]:.4f} mm {row[5]}")
        total = sum(sh.values()) or 1.0
        how = "held" if t is None else ("contact" if touching else "flight")
        print(beta, "held" if t is None else f"{t:.6f}",
              " ".join(f"{sh[k] / total:.4f}" for k in ("roll", "slide", "fly")), how, flush=True)


if __name__ == "__main__":
    main()
