#!/usr/bin/env python3
"""An independent reference for `bowl predict --model bowl` on a bare rim (issue 30): the
granule on the flat bottom of the tilted, precessing bowl, written in the *inertial* frame (no
fictitious forces, unlike the model in model-core, which works in the bowl's frame), integrated
by scipy's solve_ivp (DOP853) with its own events for the mode changes and the rim.

The bowl: R(t) = Rz(w1 t) Ry(-th) Rz(w2 t) takes bowl-frame vectors to the inertial frame (z up);
its axis n = R e3, its angular velocity W = w1 ez + w2 n, its centre O = -L Rz(w1 t) ex.
The sphere (radius a, k2 = m a^2 / (I + m a^2)): centre r, velocity v, angular velocity w, all
inertial. Contact point p = r - a n; the bowl's surface there moves at v_s = O' + W x (p - O);
the slip is v_c = v - a w x n - v_s. Per unit mass: r'' = g + N n + f, I w' = -a n x f m.
N keeps (r - O) . n = a. Sliding: f = -mu_s N v_c/|v_c|. Rolling: f makes dv_c/dt = 0
(linear in f: dv_c/dt = f / (1 - k2) + the rest). No rolling resistance here (the scenes use
mu_r = 0).

Usage: bowl_reference.py W1 W2 TH_DEG R RI A MU_S BETA_DEG [BETA_DEG ...]
prints one line per azimuth: beta_deg T_s slide_share
"""
import sys

import numpy as np
from scipy.integrate import solve_ivp

G = np.array([0.0, 0.0, -9.81])
K2 = 5.0 / 7.0


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


class Bowl:
    def __init__(self, w1, w2, th, rim, a, mu_s, rod=0.0):
        self.w1, self.w2, self.th, self.rim, self.a, self.mu_s, self.rod = w1, w2, th, rim, a, mu_s, rod

    def frame(self, t):
        rot = rz(self.w1 * t) @ ry(-self.th) @ rz(self.w2 * t)
        n = rot[:, 2]
        ez = np.array([0.0, 0.0, 1.0])
        w = self.w1 * ez + self.w2 * n
        ndot = np.cross(self.w1 * ez, n)
        nddot = np.cross(self.w1 * ez, ndot)
        wdot = self.w2 * ndot
        o = -self.rod * rz(self.w1 * t)[:, 0]
        odot = np.cross(self.w1 * ez, o)
        oddot = np.cross(self.w1 * ez, odot)
        return rot, n, ndot, nddot, w, wdot, o, odot, oddot

    def parts(self, t, y):
        r, v, om = y[0:3], y[3:6], y[6:9]
        rot, n, ndot, nddot, w, wdot, o, odot, oddot = self.frame(t)
        a = self.a
        p = r - a * n
        vs = odot + np.cross(w, p - o)
        slip = v - a * np.cross(om, n) - vs
        # (r - O) . n = a twice differentiated: (r'' - O'') . n + 2 (v - O') . n' + (r - O) . n'' = 0
        normal = -(G @ n) + oddot @ n - 2.0 * (v - odot) @ ndot - (r - o) @ nddot
        return n, ndot, w, wdot, o, odot, oddot, p, slip, normal

    def rolling_friction(self, t, y):
        """The friction that keeps the slip at zero (and the normal force)."""
        r, v, om = y[0:3], y[3:6], y[6:9]
        n, ndot, w, wdot, o, odot, oddot, p, slip, normal = self.parts(t, y)
        a = self.a
        # dv_c/dt = v' - a w' x n - a w x n' - v_s',  v_s' = O'' + W' x (p - O) + W x (p' - O'),
        # p' = v - a n'. With f = 0 the rest; f enters as f + (k2/(1-k2)) f = f / (1 - k2).
        pdot = v - a * ndot
        vs_dot = oddot + np.cross(wdot, p - o) + np.cross(w, pdot - odot)
        rest = G + normal * n - a * np.cross(om, ndot) - vs_dot
        rest_t = rest - (rest @ n) * n
        return -(1.0 - K2) * rest_t, normal

    def rhs(self, t, y, mode, direction):
        n, *_ , slip, normal = self.parts(t, y)
        if mode == "roll":
            f, normal = self.rolling_friction(t, y)
        else:
            s = np.linalg.norm(slip)
            d = slip / s if s > 1e-7 and slip @ direction > 0 else direction
            f = -self.mu_s * max(normal, 0.0) * d
        acc = G + normal * n + f
        omdot = -(K2 / (1.0 - K2)) / self.a * np.cross(n, f)
        return np.concatenate([y[3:6], acc, omdot])

    def radius(self, t, y):
        rot, n, *_ = self.frame(t)
        o = self.frame(t)[6]
        d = y[0:3] - o
        d = d - (d @ n) * n
        return np.linalg.norm(d)

    def run(self, ri, beta, horizon=10.0):
        rot, n, ndot, nddot, w, wdot, o, odot, oddot = self.frame(0.0)
        p0 = np.array([-ri * np.cos(beta), -ri * np.sin(beta), self.a])
        r0 = o + rot @ p0
        v0 = odot + np.cross(w, r0 - o)
        y = np.concatenate([r0, v0, w])
        t = 0.0
        slide_time = 0.0
        opts = dict(method="DOP853", rtol=1e-12, atol=1e-14)
        rim_event = lambda t, y, *args: self.radius(t, y) - self.rim
        rim_event.terminal, rim_event.direction = True, 1
        forced = False
        for _ in range(1000):
            f, normal = self.rolling_friction(t, y)
            slip = self.parts(t, y)[8]
            need = np.linalg.norm(f)
            if np.linalg.norm(slip) > 1e-7:
                mode, direction = "slide", slip / np.linalg.norm(slip)
            elif need > self.mu_s * normal or forced:
                # (forced: rolling just reached mu_s N; judging again at the located instant
                # could find it a hair below and roll on from there one step at a time)
                mode, direction = "slide", -f / need
            else:
                mode, direction = "roll", np.zeros(3)
            if mode == "roll":
                switch = lambda t, y, *args: (
                    np.linalg.norm(self.rolling_friction(t, y)[0])
                    - self.mu_s * self.rolling_friction(t, y)[1]
                )
                switch.direction = 1
            else:
                d0 = direction.copy()
                switch = lambda t, y, *args: self.parts(t, y)[8] @ d0
                switch.direction = -1
            switch.terminal = True
            sol = solve_ivp(
                self.rhs, (t, horizon), y, args=(mode, direction),
                events=[rim_event, switch], **opts,
            )
            if mode == "slide":
                slide_time += sol.t[-1] - t
            if sol.t_events[0].size:
                return sol.t_events[0][0], slide_time / sol.t_events[0][0]
            if not sol.t_events[1].size:
                return None, None
            t = sol.t_events[1][0]
            y = sol.y_events[1][0]
            forced = mode == "roll"
            if mode == "slide":
                # Zero slip: the spin's tangential part follows the translation.
                n, *_ , slip, normal = self.parts(t, y)
                om = y[6:9]
                y[6:9] = om + np.cross(n, slip) / self.a
        return None, None


def main():
    w1, w2, th, rim, ri, a, mu_s = map(float, sys.argv[1:8])
    bowl = Bowl(w1, w2, np.radians(th), rim, a, mu_s)
    for beta in sys.argv[8:]:
        t, share = bowl.run(ri, np.radians(float(beta)))
        print(f"{beta} {t!r} {share!r}")


if __name__ == "__main__":
    main()
