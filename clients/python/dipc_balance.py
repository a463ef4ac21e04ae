#!/usr/bin/env python3
"""Balances the double inverted pendulum on a cart (DIPC) upright with LQR, in Python.

Standard library only: lagsim_lcm (ctypes over liblcm.so.1) and the lcm-gen Python types.
The gain is designed here from the scene's parameters, the same design as the C example
dipc_lqr but written independently (plain lists, + - * / only):
  1. linearize about upright (q = 0, qd = 0) from T and U (docs/models.md):
       M0 qdd + G q = e0 u,   M0 = M(0), G = d2U/dq2 at 0 = diag(0, -(m1 l1/2 + m2 l1) g,
       -m2 l2 g / 2),  so  A = [[0, I], [-M0^-1 G, 0]],  B = [0; M0^-1 e0];
  2. discretize with a zero-order hold over the control period h (the daemon holds the
     effort over a period): exp([[A, B], [0, 0]] h) by scaling and squaring of its Taylor
     series;
  3. discrete LQR with the Riemann sum of the continuous cost (Q h, R h): the DARE solved
     by the structure-preserving doubling algorithm; K = (R h + Bd' X Bd)^-1 Bd' X Ad.
Weights default to Q = diag(5, 50, 50, 20, 700, 700), R = 1 (Bogdanov 2004). --k applies
a given gain instead (the cross-language check uses it so that every language applies
the same numbers).

Answers every state with u = -K x on theta0, computed as 0 - k0 x0 - k1 x1 - ... - k5 x5
in that order, x = (theta0, theta1, theta2, theta0_dot, theta1_dot, theta2_dot), with the
state's sim_time (lockstep-safe), until the daemon stops, falls silent for --timeout s,
or --duration s of sim time have passed; then prints a summary line. Exit status: 0 done,
1 no scene (no daemon?) or a design that does not stabilize, 2 bad usage.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lagsim_controller import Controller  # noqa: E402

N = 6


def matmul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(len(B))) for j in range(len(B[0]))]
            for i in range(len(A))]


def transpose(A):
    return [list(r) for r in zip(*A)]


def eye(n):
    return [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]


def inverse(A):
    """Gauss-Jordan with partial pivoting."""
    n = len(A)
    M = [list(A[i]) + eye(n)[i] for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(M[r][c]))
        if M[p][c] == 0.0:
            raise ZeroDivisionError("singular matrix")
        M[c], M[p] = M[p], M[c]
        piv = M[c][c]
        M[c] = [x / piv for x in M[c]]
        for r in range(n):
            if r != c and M[r][c] != 0.0:
                f = M[r][c]
                M[r] = [x - f * y for x, y in zip(M[r], M[c])]
    return [row[n:] for row in M]


def expm(A):
    """exp(A): scaling so that ||A||_1 / 2^s <= 0.5, Taylor to order 20, s squarings."""
    n = len(A)
    norm = max(sum(abs(A[i][j]) for i in range(n)) for j in range(n))
    s = 0
    while norm > 0.5:
        norm /= 2.0
        s += 1
    As = [[x / 2.0 ** s for x in row] for row in A]
    E, T = eye(n), eye(n)
    for k in range(1, 21):
        T = [[x / k for x in row] for row in matmul(T, As)]
        E = [[e + t for e, t in zip(er, tr)] for er, tr in zip(E, T)]
    for _ in range(s):
        E = matmul(E, E)
    return E


def linearize(p):
    """A, B of the DIPC about upright (see the module's docstring)."""
    m0, m1, m2, l1, l2, I1, I2, g = (p[k] for k in ("m0", "m1", "m2", "l1", "l2", "I1", "I2", "g"))
    a = m1 * l1 / 2 + m2 * l1
    M0 = [[m0 + m1 + m2, a, m2 * l2 / 2],
          [a, m1 * l1 * l1 / 4 + m2 * l1 * l1 + I1, m2 * l1 * l2 / 2],
          [m2 * l2 / 2, m2 * l1 * l2 / 2, m2 * l2 * l2 / 4 + I2]]
    G = [0.0, -a * g, -m2 * l2 * g / 2]
    Mi = inverse(M0)
    A = [[0.0] * N for _ in range(N)]
    B = [[0.0] for _ in range(N)]
    for i in range(3):
        A[i][3 + i] = 1.0
        for j in range(3):
            A[3 + i][j] = -Mi[i][j] * G[j]
        B[3 + i][0] = Mi[i][0]
    return A, B


def c2d(A, B, h):
    """Zero-order hold: Ad = e^(A h), Bd = int_0^h e^(A s) ds B."""
    Z = [[A[i][j] * h for j in range(N)] + [B[i][0] * h] for i in range(N)] + [[0.0] * (N + 1)]
    E = expm(Z)
    return [row[:N] for row in E[:N]], [[row[N]] for row in E[:N]]


def dare(A, B, Q, R):
    """X of X = A'XA - A'XB (R + B'XB)^-1 B'XA + Q by doubling (scalar input)."""
    Ak, Gk, Hk = A, [[B[i][0] * B[j][0] / R for j in range(N)] for i in range(N)], Q
    for _ in range(100):
        W = inverse([[(1.0 if i == j else 0.0) + sum(Gk[i][k] * Hk[k][j] for k in range(N))
                      for j in range(N)] for i in range(N)])
        AW = matmul(Ak, W)
        An = matmul(AW, Ak)
        Gn = [[x + y for x, y in zip(r1, r2)]
              for r1, r2 in zip(Gk, matmul(matmul(AW, Gk), transpose(Ak)))]
        Hn = [[x + y for x, y in zip(r1, r2)]
              for r1, r2 in zip(Hk, matmul(matmul(transpose(Ak), Hk), matmul(W, Ak)))]
        diff = max(abs(x - y) for r1, r2 in zip(Hn, Hk) for x, y in zip(r1, r2))
        size = max(abs(x) for r in Hn for x in r)
        Ak, Gk, Hk = An, Gn, Hn
        if diff <= 1e-14 * size:
            return Hk
    raise ArithmeticError("the Riccati doubling did not converge")


def design(p, h, qw, r):
    A, B = linearize(p)
    Ad, Bd = c2d(A, B, h)
    Qd = [[qw[i] * h if i == j else 0.0 for j in range(N)] for i in range(N)]
    X = dare(Ad, Bd, Qd, r * h)
    XB = matmul(X, Bd)
    den = r * h + sum(Bd[i][0] * XB[i][0] for i in range(N))
    K = [x / den for x in matmul(transpose(XB), Ad)[0]]
    return Ad, Bd, K


def closed_loop(Ad, Bd, K):
    return [[Ad[i][j] - Bd[i][0] * K[j] for j in range(N)] for i in range(N)]


def parse_list(s, what):
    try:
        v = [float(x) for x in s.split(",")]
    except ValueError:
        v = []
    if len(v) != N or not all(math.isfinite(x) for x in v):
        raise SystemExit("dipc_balance.py: %s wants %d comma-separated numbers" % (what, N))
    return v


def main():
    ctl = Controller("dipc_balance.py", "DIPC", "dipc", description=__doc__.split("\n")[0])
    ctl.parser.add_argument("--q", dest="qweights", default="5,50,50,20,700,700",
                            help="state weights (default 5,50,50,20,700,700)")
    ctl.parser.add_argument("--r", type=float, default=1.0, help="input weight (default 1)")
    ctl.parser.add_argument("--k", default=None,
                            help="apply this gain k0,...,k5 instead of designing one")
    a = ctl.start()
    qw = parse_list(a.qweights, "--q")
    if not (a.r > 0 and math.isfinite(a.r)) or min(qw) < 0:
        ctl.parser.error("--r must be > 0 and the --q weights >= 0")
    h = ctl.scene.control_period
    Ad, Bd, K = design(ctl.params, h, qw, a.r)
    print("dipc_balance.py: discrete LQR (h = %g s): K = [%s]"
          % (h, ", ".join("%.17g" % k for k in K)), flush=True)
    if a.k is not None:
        K = parse_list(a.k, "--k")
        print("dipc_balance.py: applying the given gain K = [%s]"
              % ", ".join("%.17g" % k for k in K), flush=True)
    # the sampled closed loop must be stable: powers of Ad - Bd K must shrink
    P = closed_loop(Ad, Bd, K)
    for _ in range(12):  # P^4096
        P = matmul(P, P)
    if not max(abs(x) for r in P for x in r) < 1e-3:
        sys.stderr.write("dipc_balance.py: this gain does not stabilize the sampled loop\n")
        return 1

    names = ["theta0"]
    states = 0
    t_first = t_last = float("nan")
    t_report = -float("inf")
    peak = [0.0, 0.0, 0.0]
    max_u = 0.0
    end = [float("nan")] * 3
    x_first = None
    idx = None
    for st in ctl.states():
        try:
            idx = [st.name.index(j) for j in ("theta0", "theta1", "theta2")]
        except ValueError:
            continue
        x = [st.position[i] for i in idx] + [st.velocity[i] for i in idx]
        u = 0.0
        for k in range(N):
            u -= K[k] * x[k]
        ctl.command(st.sim_time, names, [u])

        if states == 0:
            t_first = st.sim_time
            x_first = x
        states += 1
        t_last = st.sim_time
        for k in range(3):
            peak[k] = max(peak[k], abs(x[k]))
        max_u = max(max_u, abs(u))
        end = x[:3]
        if not a.q and st.sim_time - t_report >= 1.0:
            t_report = st.sim_time
            print("t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f"
                  % (st.sim_time, x[0], x[1], x[2], u), flush=True)
    # the linearized sampled loop x+ = (Ad - Bd K) x from the first state, as long
    pred = [0.0, 0.0, 0.0]
    if x_first is not None:
        Acl = closed_loop(Ad, Bd, K)
        xl = x_first
        for _ in range(states):
            for k in range(3):
                pred[k] = max(pred[k], abs(xl[k]))
            xl = [sum(Acl[i][j] * xl[j] for j in range(N)) for i in range(N)]
    return ctl.finish(
        "states=%d t_first=%.6f t_last=%.6f max_abs_theta0=%.6g max_abs_theta1=%.6g "
        "max_abs_theta2=%.6g max_abs_effort=%.6g end_theta1=%.3g end_theta2=%.3g "
        "pred_max_abs_theta0=%.6g pred_max_abs_theta1=%.6g pred_max_abs_theta2=%.6g"
        % (states, t_first, t_last, peak[0], peak[1], peak[2], max_u, end[1], end[2],
           pred[0], pred[1], pred[2]))


if __name__ == "__main__":
    sys.exit(main())
