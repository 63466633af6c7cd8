#!/usr/bin/env python3
"""A single sphere hitting a still plane obliquely in MuJoCo, beside the closed form of a rigid
sphere's impact with Coulomb friction (Routh; Stronge, "Impact Mechanics", ch. 3/5): does the
reference's soft contact give the tangential impulse that Coulomb friction gives?

The sphere (radius a, solid: I = 2/5 m a^2, k2 = m a^2 / (I + m a^2) = 5/7) comes in with
centre velocity (vx, 0, -vz) and spin wy about the y axis (no gravity), with the contact
settings of bowl_mujoco.py (elliptic cone, sliding mu, solref 0.0005 1, solimp 0.99 0.999
0.0001, timestep 1e-5). Read off once the contact has ended (normal force zero for 1 ms).

Closed form (per unit mass; slip of the contact point v_c = vx - a wy, normal impulse
J_n = (1 + e) vz): the slip stops if (1 - k2) |v_c| <= mu J_n (a sticking impact: vx' = vx -
(1 - k2) v_c, rolling after), else J_t = mu J_n against the slip (a sliding impact: vx' = vx -
mu J_n sign(v_c)); the spin takes a dwy = -(k2 / (1 - k2)) J_t (torque of the impulse at -a e_z).

Usage: impact_mujoco.py [IMPRATIO [TIMECONST_S [NOSLIP_ITERATIONS]]]
prints one line per case: vx vz a*wy | MuJoCo vx' a*wy' e | Routh vx' a*wy' (e MuJoCo's) | regime
"""
import sys

import mujoco
import numpy as np

A = 0.003
MU = 0.4
DT = 1e-5


def xml(impratio, tc, noslip, dampratio=1.0):
    return f"""
<mujoco>
  <option timestep="{DT}" gravity="0 0 0" cone="elliptic" integrator="implicitfast"
          impratio="{impratio}" noslip_iterations="{noslip}"/>
  <default>
    <geom condim="6" friction="{MU} 0 0" solref="{tc} {dampratio}" solimp="0.99 0.999 0.0001"/>
  </default>
  <worldbody>
    <geom type="plane" size="1 1 0.1"/>
    <body name="ball" pos="0 0 {A + 1e-4}">
      <freejoint/>
      <geom type="sphere" size="{A}" mass="0.001"/>
    </body>
  </worldbody>
</mujoco>"""


def mujoco_impact(vx, vz, swy, impratio, tc, noslip, dampratio=1.0):
    m = mujoco.MjModel.from_xml_string(xml(impratio, tc, noslip, dampratio))
    d = mujoco.MjData(m)
    d.qvel[0:3] = [vx, 0.0, -vz]
    d.qvel[3:6] = [0.0, swy / A, 0.0]
    touched, quiet = False, 0
    for _ in range(200000):
        mujoco.mj_step(m, d)
        if d.ncon > 0:
            f = np.zeros(6)
            mujoco.mj_contactForce(m, d, 0, f)
            if f[0] > 0:
                touched, quiet = True, 0
                continue
        if touched:
            quiet += 1
            if quiet > 100:
                break
    w = d.xmat[1].reshape(3, 3) @ d.qvel[3:6] if False else d.qvel[3:6]
    return d.qvel[0], A * w[1], d.qvel[2] / vz


def routh(vx, vz, swy, e, mu=MU, k2=5.0 / 7.0):
    # contact point velocity along x: centre + w x (-a ez) = vx - a wy
    vc = vx - swy
    jn = (1.0 + e) * vz
    if (1.0 - k2) * abs(vc) <= mu * jn:
        jt = -(1.0 - k2) * vc
        regime = "stick"
    else:
        jt = -mu * jn * np.sign(vc)
        regime = "slide"
    # I dw = (-a ez) x (m jt ex) = -a m jt ey  ->  a dwy = -(m a^2 / I) jt = -(k2/(1-k2)) jt
    return vx + jt, swy - (k2 / (1.0 - k2)) * jt, regime


def main():
    impratio = float(sys.argv[1]) if len(sys.argv) > 1 else 1.0
    tc = float(sys.argv[2]) if len(sys.argv) > 2 else 0.0005
    noslip = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    print(f"# impratio {impratio}, solref timeconst {tc} s, noslip_iterations {noslip}, mu {MU}")
    print("# vx vz a*wy | mujoco: vx' a*wy' e | routh(e mujoco): vx' a*wy' regime | "
          "J_t mujoco / routh")
    for vz in (0.6,):
        for vx, swy in ((0.1, 0.0), (0.3, 0.0), (0.6, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0),
                        (0.5, -0.5), (0.5, -0.25), (0.5, 0.3)):
            mx, mw, me = mujoco_impact(vx, vz, swy, impratio, tc, noslip)
            rx, rw, reg = routh(vx, vz, swy, me)
            jr = rx - vx
            print(f"{vx:.3f} {vz:.3f} {swy:+.3f} | {mx:.4f} {mw:+.4f} {me:.3f} | "
                  f"{rx:.4f} {rw:+.4f} {reg} | {(mx - vx) / jr if jr else float('nan'):.3f}",
                  flush=True)


if __name__ == "__main__":
    main()
