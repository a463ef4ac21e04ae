package lagsim.examples;

import java.util.Map;

import lagsim.joint_state_t;

/**
 * Balances the double inverted pendulum on a cart (DIPC) upright with LQR, in Java.
 *
 * The same design as clients/python/dipc_balance.py (see there), line for line:
 * linearize about upright from T and U, zero-order hold over the control period,
 * discrete LQR with cost (Q h, R h) by Riccati doubling. --k applies a given gain.
 * Answers every state with u = 0 - k0 x0 - k1 x1 - ... - k5 x5 on theta0 (in that order),
 * x = (theta0, theta1, theta2, theta0_dot, theta1_dot, theta2_dot), with the state's
 * sim_time (lockstep-safe), until the daemon stops, falls silent for --timeout s, or
 * --duration s of sim time have passed; then prints a summary line.
 *
 * <pre>
 *   java -cp /usr/share/java/lcm.jar:build/lagsim_types.jar:build/lagsim_examples.jar \
 *        lagsim.examples.DipcBalance [--prefix DIPC] [--k k0,...,k5]
 * </pre>
 */
public final class DipcBalance {
    static final int N = 6;

    static double[][] zeros(int r, int c) { return new double[r][c]; }

    static double[][] eye(int n) {
        double[][] M = zeros(n, n);
        for (int i = 0; i < n; i++) M[i][i] = 1.0;
        return M;
    }

    static double[][] matmul(double[][] A, double[][] B) {
        double[][] C = zeros(A.length, B[0].length);
        for (int i = 0; i < A.length; i++)
            for (int j = 0; j < B[0].length; j++) {
                double s = 0;
                for (int k = 0; k < B.length; k++) s = s + A[i][k] * B[k][j];
                C[i][j] = s;
            }
        return C;
    }

    static double[][] transpose(double[][] A) {
        double[][] T = zeros(A[0].length, A.length);
        for (int i = 0; i < A.length; i++)
            for (int j = 0; j < A[0].length; j++) T[j][i] = A[i][j];
        return T;
    }

    static double[][] add(double[][] A, double[][] B) {
        double[][] C = zeros(A.length, A[0].length);
        for (int i = 0; i < A.length; i++)
            for (int j = 0; j < A[0].length; j++) C[i][j] = A[i][j] + B[i][j];
        return C;
    }

    /** Gauss-Jordan with partial pivoting. */
    static double[][] inverse(double[][] A) {
        int n = A.length;
        double[][] M = zeros(n, 2 * n);
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++) M[i][j] = A[i][j];
            M[i][n + i] = 1.0;
        }
        for (int c = 0; c < n; c++) {
            int p = c;
            for (int r = c + 1; r < n; r++)
                if (Math.abs(M[r][c]) > Math.abs(M[p][c])) p = r;
            if (M[p][c] == 0.0) throw new ArithmeticException("singular matrix");
            double[] t = M[c]; M[c] = M[p]; M[p] = t;
            double piv = M[c][c];
            for (int j = 0; j < 2 * n; j++) M[c][j] = M[c][j] / piv;
            for (int r = 0; r < n; r++)
                if (r != c && M[r][c] != 0.0) {
                    double f = M[r][c];
                    for (int j = 0; j < 2 * n; j++) M[r][j] = M[r][j] - f * M[c][j];
                }
        }
        double[][] R = zeros(n, n);
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) R[i][j] = M[i][n + j];
        return R;
    }

    /** exp(A): scaling so that ||A||_1 / 2^s <= 0.5, Taylor to order 20, s squarings. */
    static double[][] expm(double[][] A) {
        int n = A.length;
        double norm = 0;
        for (int j = 0; j < n; j++) {
            double s = 0;
            for (int i = 0; i < n; i++) s = s + Math.abs(A[i][j]);
            norm = Math.max(norm, s);
        }
        int s = 0;
        while (norm > 0.5) {
            norm = norm / 2.0;
            s++;
        }
        double scale = Math.scalb(1.0, s);
        double[][] As = zeros(n, n);
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) As[i][j] = A[i][j] / scale;
        double[][] E = eye(n), T = eye(n);
        for (int k = 1; k <= 20; k++) {
            T = matmul(T, As);
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) T[i][j] = T[i][j] / k;
            E = add(E, T);
        }
        for (int k = 0; k < s; k++) E = matmul(E, E);
        return E;
    }

    /** A and B of the DIPC about upright: M0 qdd + G q = e0 u. */
    static double[][][] linearize(Map<String, Double> p) {
        double m0 = p.get("m0"), m1 = p.get("m1"), m2 = p.get("m2"), l1 = p.get("l1"),
               l2 = p.get("l2"), I1 = p.get("I1"), I2 = p.get("I2"), g = p.get("g");
        double a = m1 * l1 / 2 + m2 * l1;
        double[][] M0 = {{m0 + m1 + m2, a, m2 * l2 / 2},
                         {a, m1 * l1 * l1 / 4 + m2 * l1 * l1 + I1, m2 * l1 * l2 / 2},
                         {m2 * l2 / 2, m2 * l1 * l2 / 2, m2 * l2 * l2 / 4 + I2}};
        double[] G = {0.0, -a * g, -m2 * l2 * g / 2};
        double[][] Mi = inverse(M0);
        double[][] A = zeros(N, N), B = zeros(N, 1);
        for (int i = 0; i < 3; i++) {
            A[i][3 + i] = 1.0;
            for (int j = 0; j < 3; j++) A[3 + i][j] = -Mi[i][j] * G[j];
            B[3 + i][0] = Mi[i][0];
        }
        return new double[][][] {A, B};
    }

    static double[][][] c2d(double[][] A, double[][] B, double h) {
        double[][] Z = zeros(N + 1, N + 1);
        for (int i = 0; i < N; i++) {
            for (int j = 0; j < N; j++) Z[i][j] = A[i][j] * h;
            Z[i][N] = B[i][0] * h;
        }
        double[][] E = expm(Z);
        double[][] Ad = zeros(N, N), Bd = zeros(N, 1);
        for (int i = 0; i < N; i++) {
            for (int j = 0; j < N; j++) Ad[i][j] = E[i][j];
            Bd[i][0] = E[i][N];
        }
        return new double[][][] {Ad, Bd};
    }

    static double[][] dare(double[][] A, double[][] B, double[][] Q, double R) {
        double[][] Ak = A, Gk = zeros(N, N), Hk = Q;
        for (int i = 0; i < N; i++)
            for (int j = 0; j < N; j++) Gk[i][j] = B[i][0] * B[j][0] / R;
        for (int it = 0; it < 100; it++) {
            double[][] W = inverse(add(eye(N), matmul(Gk, Hk)));
            double[][] AW = matmul(Ak, W);
            double[][] An = matmul(AW, Ak);
            double[][] Gn = add(Gk, matmul(matmul(AW, Gk), transpose(Ak)));
            double[][] Hn = add(Hk, matmul(matmul(transpose(Ak), Hk), matmul(W, Ak)));
            double diff = 0, size = 0;
            for (int i = 0; i < N; i++)
                for (int j = 0; j < N; j++) {
                    diff = Math.max(diff, Math.abs(Hn[i][j] - Hk[i][j]));
                    size = Math.max(size, Math.abs(Hn[i][j]));
                }
            Ak = An;
            Gk = Gn;
            Hk = Hn;
            if (diff <= 1e-14 * size) return Hk;
        }
        throw new ArithmeticException("the Riccati doubling did not converge");
    }

    static double[][] closedLoop(double[][] Ad, double[][] Bd, double[] K) {
        double[][] P = zeros(N, N);
        for (int i = 0; i < N; i++)
            for (int j = 0; j < N; j++) P[i][j] = Ad[i][j] - Bd[i][0] * K[j];
        return P;
    }

    static String fmt(double[] v) {
        StringBuilder b = new StringBuilder();
        for (int i = 0; i < v.length; i++) b.append(i > 0 ? ", " : "").append(v[i]);
        return b.toString();
    }

    public static void main(String[] args) throws Exception {
        Controller ctl = new Controller("DipcBalance", "DIPC", "dipc");
        ctl.option("q", "5,50,50,20,700,700", "state weights");
        ctl.option("r", "1", "input weight");
        ctl.option("k", "", "apply this gain k0,...,k5 instead of designing one");
        ctl.start(args);
        double[] qw = ctl.list("q", N);
        double r = ctl.number("r");
        if (!(r > 0)) ctl.usageError("--r must be > 0");
        for (double w : qw)
            if (!(w >= 0)) ctl.usageError("--q wants weights >= 0");

        double h = ctl.scene.control_period;
        double[][][] AB = linearize(ctl.params);
        double[][][] ABd = c2d(AB[0], AB[1], h);
        double[][] Ad = ABd[0], Bd = ABd[1];
        double[][] Qd = zeros(N, N);
        for (int i = 0; i < N; i++) Qd[i][i] = qw[i] * h;
        double[][] X = dare(Ad, Bd, Qd, r * h);
        double[][] XB = matmul(X, Bd);
        double den = r * h;
        for (int i = 0; i < N; i++) den = den + Bd[i][0] * XB[i][0];
        double[] KA = matmul(transpose(XB), Ad)[0];
        double[] K = new double[N];
        for (int i = 0; i < N; i++) K[i] = KA[i] / den;
        System.out.printf("DipcBalance: discrete LQR (h = %s s): K = [%s]%n", h, fmt(K));
        if (!ctl.get("k").isEmpty()) {
            K = ctl.list("k", N);
            System.out.println("DipcBalance: applying the given gain K = [" + fmt(K) + "]");
        }
        System.out.flush();
        double[][] P = closedLoop(Ad, Bd, K);
        for (int i = 0; i < 12; i++) P = matmul(P, P); // P^4096 must have shrunk
        double pmax = 0;
        for (double[] row : P)
            for (double v : row) pmax = Math.max(pmax, Math.abs(v));
        if (!(pmax < 1e-3)) {
            System.err.println("DipcBalance: this gain does not stabilize the sampled loop");
            System.exit(1);
        }

        String[] names = {"theta0"};
        long states = 0;
        double tFirst = Double.NaN, tLast = Double.NaN, tReport = Double.NEGATIVE_INFINITY, maxU = 0;
        double[] peak = new double[3], xEnd = {Double.NaN, Double.NaN, Double.NaN}, xFirst = null;
        joint_state_t st;
        while ((st = ctl.nextState()) != null) {
            int[] idx = {Controller.joint(st, "theta0"), Controller.joint(st, "theta1"),
                         Controller.joint(st, "theta2")};
            if (idx[0] < 0 || idx[1] < 0 || idx[2] < 0) continue;
            double[] x = new double[N];
            for (int k = 0; k < 3; k++) {
                x[k] = st.position[idx[k]];
                x[3 + k] = st.velocity[idx[k]];
            }
            double u = 0.0;
            for (int k = 0; k < N; k++) u = u - K[k] * x[k];
            ctl.command(st.sim_time, names, new double[] {u});

            if (states == 0) {
                tFirst = st.sim_time;
                xFirst = x;
            }
            states++;
            tLast = st.sim_time;
            for (int k = 0; k < 3; k++) peak[k] = Math.max(peak[k], Math.abs(x[k]));
            maxU = Math.max(maxU, Math.abs(u));
            xEnd = x;
            if (!ctl.quiet && st.sim_time - tReport >= 1.0) {
                tReport = st.sim_time;
                System.out.printf("t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f%n", st.sim_time, x[0],
                                  x[1], x[2], u);
            }
        }
        // the linearized sampled loop x+ = (Ad - Bd K) x from the first state, as long
        double[] pred = new double[3];
        if (xFirst != null) {
            double[][] Acl = closedLoop(Ad, Bd, K);
            double[] xl = xFirst;
            for (long s = 0; s < states; s++) {
                for (int k = 0; k < 3; k++) pred[k] = Math.max(pred[k], Math.abs(xl[k]));
                double[] xn = new double[N];
                for (int i = 0; i < N; i++) {
                    double sum = 0;
                    for (int j = 0; j < N; j++) sum = sum + Acl[i][j] * xl[j];
                    xn[i] = sum;
                }
                xl = xn;
            }
        }
        System.exit(ctl.finish(String.format(java.util.Locale.ROOT,
            "states=%d t_first=%.6f t_last=%.6f max_abs_theta0=%.6g max_abs_theta1=%.6g "
            + "max_abs_theta2=%.6g max_abs_effort=%.6g end_theta1=%.3g end_theta2=%.3g "
            + "pred_max_abs_theta0=%.6g pred_max_abs_theta1=%.6g pred_max_abs_theta2=%.6g",
            states, tFirst, tLast, peak[0], peak[1], peak[2], maxU, xEnd[1], xEnd[2], pred[0],
            pred[1], pred[2])));
    }
}
