# The sliding incline in the bowl's rotation, to second order in the speeds (docs/model.md §12,
# "The sliding incline's second order, and the corrected incline"; model-core
# choose::incline_rotation, Orders::sliding). Truncated power series in eps (the speeds' scale)
# by hand, orders 0, 1, 2; each order's residual against the equations is printed (all zero).
# Run: python3 docs/derivations/sliding_incline.py (sympy; about 15 s). Not run by CI.
# The equations are §10's sliding sphere in the bowl frame of §9 (x, y on the bottom, the slip
# (ux - sy, uy + sx) with s = a omega, the friction -mu_s N along the slip, the spin driven by
# kappa = k2 / (1 - k2) of it).
import sympy as sp
t = sp.Symbol('t', positive=True)
g, s, c, w1, w2, mu, kap, a, p0x, p0y = sp.symbols('g s c w1 w2 mu kappa a p0x p0y', real=True)
U, lam = sp.symbols('U lam', positive=True)
Nn, G = g*c, g*s
A = G - mu*Nn                 # the sliding drive
Uexpr = G - mu*Nn*(1 + kap)   # the slip's rate at order 0 (U)
Z = [0, 0, 0]

def mul(p, q):
    return [sp.expand(sum(p[i]*q[n-i] for i in range(n+1))) for n in range(3)]
def add(*ps):
    return [sp.expand(sum(p[n] for p in ps)) for n in range(3)]
def sc(k, p):
    return [sp.expand(k*x) for x in p]
def cross(u, v):
    return [add(mul(u[1], v[2]), sc(-1, mul(u[2], v[1]))),
            add(mul(u[2], v[0]), sc(-1, mul(u[0], v[2]))),
            add(mul(u[0], v[1]), sc(-1, mul(u[1], v[0])))]
def dot(u, v):
    return add(*[mul(u[i], v[i]) for i in range(3)])
def const(x):
    return [x, 0, 0]

psi1 = w2*t  # psi = eps w2 t
cos_ = [1, 0, -psi1**2/2]
sin_ = [0, psi1, 0]
Om = [sc(w1*s, mul([0, 1, 0], cos_)), sc(-w1*s, mul([0, 1, 0], sin_)), [0, w1*c + w2, 0]]
al = [sc(-w1*w2*s, mul([0, 0, 1], sin_)), sc(-w1*w2*s, mul([0, 0, 1], cos_)), Z]
gB = [sc(-g*s, cos_), sc(g*s, sin_), const(-g*c)]

def rhs(st):
    x, y, ux, uy, sx, sy, sz = st
    p = [x, y, const(a)]
    Odp = dot(Om, p)
    OO = dot(Om, Om)
    C = [add(mul(Om[i], Odp), sc(-1, mul(OO, p[i]))) for i in range(3)]
    E = cross(al, p)
    u3 = [ux, uy, Z]
    Ou = cross(Om, u3)
    N = add(const(g*c), E[2], C[2], sc(2, add(mul(Om[0], uy), sc(-1, mul(Om[1], ux)))))
    vcx, vcy = add(ux, sc(-1, sy)), add(uy, sx)
    V = U*t
    dx = [0, vcx[1], vcx[2]]   # vcx = -V + dx (order 0 checked below)
    dy = vcy
    dirx = [-1, 0, sp.expand(dy[1]**2/(2*V**2))]
    diry = [0, sp.expand(dy[1]/V), sp.expand(dy[2]/V + dx[1]*dy[1]/V**2)]
    fx = sc(-mu, mul(N, dirx))
    fy = sc(-mu, mul(N, diry))
    Os = cross(Om, [sx, sy, sz])
    dux = add(gB[0], sc(-1, E[0]), sc(-1, C[0]), sc(-2, Ou[0]), fx)
    duy = add(gB[1], sc(-1, E[1]), sc(-1, C[1]), sc(-2, Ou[1]), fy)
    dsx = add(sc(kap, fy), sc(-a, al[0]), sc(-1, Os[0]))
    dsy = add(sc(-kap, fx), sc(-a, al[1]), sc(-1, Os[1]))
    dsz = add(sc(-a, al[2]), sc(-1, Os[2]))
    return [ux, uy, dux, duy, dsx, dsy, dsz], vcx

integ = lambda e: sp.integrate(sp.expand(e), (t, 0, t))
def solve_v(P):
    # v' + lam v / t = P(t), P a polynomial in t: the solution regular at 0.
    P = sp.Poly(sp.expand(P), t)
    return sum(cf*t**(k+1)/(k+1+lam) for (k,), cf in P.terms())

# Order 0: sliding straight down e1 from p0.
st = [[p0x - A*t**2/2, 0, 0], [p0y, 0, 0], [-A*t, 0, 0], [0, 0, 0], [0, 0, 0], [-kap*mu*Nn*t, 0, 0], [0, 0, 0]]
r, vcx = rhs(st)
print('order 0 residual', [sp.simplify((r[i][0] - sp.diff(st[i][0], t)).subs(U, Uexpr)) for i in range(7)],
      'slip', sp.simplify(vcx[0] + Uexpr*t))
unk = sp.symbols('X Y UX UY SX SY SZ')
for n in [1, 2]:
    trial = [[st[i][0], st[i][1], st[i][2]] for i in range(7)]
    for i in range(7):
        trial[i][n] = unk[i]
    r, _ = rhs(trial)
    rn = [sp.expand(r[i][n]) for i in range(7)]
    # Only the across block couples to the unknowns, through the friction's -mu Nn (UY + SX) / (U t).
    for i in range(2, 7):
        for j, q in enumerate(unk):
            d = sp.simplify(sp.diff(rn[i], q))
            if d != 0:
                print(f'order {n}: eq {i} depends on {q}: {d}')
    z = {q: 0 for q in unk}
    ku, ks = rn[3].subs(z), rn[4].subs(z)
    v = solve_v(ku + ks)
    fy = -mu*Nn*v/(U*t)
    UYn = integ(sp.expand(ku + fy))
    SXn = integ(sp.expand(ks + kap*fy))
    UXn = integ(rn[2].subs(z))
    SYn = integ(rn[5].subs(z))
    SZn = integ(rn[6].subs(z))
    sol = [integ(UXn), integ(UYn), UXn, UYn, SXn, SYn, SZn]
    sol = [sp.expand(e) for e in sol]
    for i in range(7):
        st[i][n] = sol[i]
    # Check the order with the friction's exact linear part (lam substituted).
    r, _ = rhs(st)
    res = [sp.simplify((r[i][n] - sp.diff(st[i][n], t)).subs(lam, (1+kap)*mu*Nn/U)) for i in range(7)]
    print('order', n, 'residual', res)
names = ['x', 'y', 'ux', 'uy', 'sx', 'sy', 'sz']
for n in [1, 2]:
    for nm, i in zip(names, range(7)):
        e = sp.collect(sp.expand(st[i][n]), [t, p0x, p0y])
        print(f'{nm}{n} =', e)
