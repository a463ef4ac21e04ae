/*
 * Small dense linear algebra for LQR design: linearization of a lagsim model about an
 * equilibrium, the continuous (CARE) and discrete (DARE) algebraic Riccati equations,
 * zero-order-hold discretization, and eigenvalues of a real square matrix.
 *
 * Sizes are tiny (n <= LAG_LQR_MAX_N states, m <= LAG_LQR_MAX_M inputs): fixed-size
 * scratch arrays on the stack, LAPACK (LAPACKE) for the dense kernels, no printing. Matrices
 * are row-major. Functions return 0 on success, a negative code on failure.
 */
#ifndef LAGSIM_CLIENTS_LQR_H
#define LAGSIM_CLIENTS_LQR_H

#include "lagsim/lagsim.h"

#define LAG_LQR_MAX_N LAG_MAX_STATE /* 6 states */
#define LAG_LQR_MAX_M LAG_MAX_DOF   /* 3 inputs */

enum {
    LAG_LQR_OK = 0,
    LAG_LQR_ERR_ARG = -1,       /* size out of range */
    LAG_LQR_ERR_SINGULAR = -2,  /* a matrix to invert was singular */
    LAG_LQR_ERR_NOCONV = -3,    /* an iteration did not converge */
    LAG_LQR_ERR_MODEL = -4      /* the model's forward dynamics failed */
};

/* Linearizes the model's first-order dynamics y = (q, qd), ydot = (qd, qdd(q, qd, tau))
 * about (q0, qd0, tau0) by central finite differences of lag_model_forward.
 * The inputs are the model's coordinates listed in `inputs` (m of them, indices into q);
 * tau0 may be NULL (zero). n = 2 * model->nq.
 * OUT: A (n x n), B (n x m). */
int lag_lqr_linearize(const lag_model *model, const double *q0, const double *qd0,
                      const double *tau0, int m, const int *inputs, double *A, double *B);

/* Continuous LQR: the stabilizing solution X of
 *   A^T X + X A - X B R^-1 B^T X + Q = 0
 * (matrix sign function of the Hamiltonian with determinant scaling, then
 * Newton-Kleinman refinement, each step's Lyapunov equation by Bartels-Stewart) and the gain K = R^-1 B^T X (m x n), so that u = -K x.
 * OUT: X (n x n), K (m x n). */
int lag_lqr_care(int n, int m, const double *A, const double *B, const double *Q,
                 const double *R, double *X, double *K);

/* Relative residual ||A^T X + X A - X B R^-1 B^T X + Q||_F / ||Q||_F. */
double lag_lqr_care_residual(int n, int m, const double *A, const double *B, const double *Q,
                             const double *R, const double *X);

/* Zero-order-hold discretization over h seconds: Ad = e^{A h}, Bd = int_0^h e^{A s} ds B
 * (exponential of the augmented matrix [[A, B], [0, 0]] h, scaling and squaring with a
 * Taylor series). OUT: Ad (n x n), Bd (n x m). */
int lag_lqr_c2d(int n, int m, const double *A, const double *B, double h, double *Ad,
                double *Bd);

/* Discrete LQR: the stabilizing solution X of
 *   X = Ad^T X Ad - Ad^T X Bd (R + Bd^T X Bd)^-1 Bd^T X Ad + Q
 * by the structure-preserving doubling algorithm (quadratic convergence), and the gain
 * K = (R + Bd^T X Bd)^-1 Bd^T X Ad, so that u_k = -K x_k. OUT: X (n x n), K (m x n). */
int lag_lqr_dare(int n, int m, const double *Ad, const double *Bd, const double *Q,
                 const double *R, double *X, double *K);

/* Relative residual of the DARE above, ||X - rhs||_F / ||Q||_F. */
double lag_lqr_dare_residual(int n, int m, const double *Ad, const double *Bd,
                             const double *Q, const double *R, const double *X);

/* Closed-loop matrix Acl = A - B K. OUT: Acl (n x n). */
void lag_lqr_closed_loop(int n, int m, const double *A, const double *B, const double *K,
                         double *Acl);

/* Eigenvalues of a real n x n matrix (n <= 2 * LAG_LQR_MAX_N), by LAPACK's dgeev
 * (balancing, Hessenberg form, shifted QR). Sorted by real part, then imaginary part.
 * OUT: re (n), im (n). */
int lag_lqr_eig(int n, const double *A, double *re, double *im);

#endif
