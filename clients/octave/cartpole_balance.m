function cartpole_balance(varargin)
%CARTPOLE_BALANCE  Balances the cart-pole upright with LQR, from MATLAB or GNU Octave.
%
%   cartpole_balance --prefix CARTPOLE --duration 20
%   octave --eval "cartpole_balance --prefix CARTPOLE -q"   % <build>/octave on the path
%
%   The design, from the scene's parameters (m0, m1, l1, I1, g) alone:
%     1. linearize about upright from T and U (docs/models.md, the cart-pole): with
%        a = l1/2, k = m1 a, J = m1 a^2 + I1, M(0) = [m0 + m1, k; k, J] and
%        dg/dq at 0 = [0 0; 0 -k g], so A = [0 I; -M(0)\dg/dq 0], B = [0; M(0)\(1, 0)];
%     2. --gain discrete (the default): the zero-order hold over the control period h,
%        expm([A B; 0 0] h), and the discrete LQR with cost (Q h, R h) (lagsim_dlqr:
%        dlqr); --gain continuous: lqr of (A, B, Q, R) (the Control System Toolbox's in
%        MATLAB, octave-control's in GNU Octave), held over each period by the daemon.
%   Weights default to Q = I, R = 1 (lqr_balance's defaults). Either gain must make the
%   sampled loop Ad - Bd K stable. Answers every state with F = -K (x, theta, x_dot,
%   theta_dot) on the cart, and prints a summary with lqr_balance's keys: max_abs_x,
%   max_abs_theta, end_x, end_theta and the linearized sampled loop's peaks from the first
%   state (pred_max_abs_x, pred_max_abs_theta), and k_x, the gain on x (for the
%   continuous design it is -sqrt(q_x / r): see tests/languages.cmake). Options: those of lagsim_controller,
%   --q, --r, --gain, --k.
ctl = lagsim_controller('cartpole_balance', 'CARTPOLE', 'cartpole');
ctl.option('q', '1,1,1,1', 'state weights (x, theta, x_dot, theta_dot)');
ctl.option('r', '1', 'input weight');
ctl.option('gain', 'discrete', 'discrete (dlqr of the sampled plant) or continuous (lqr)');
ctl.option('k', '', 'apply this gain k0,...,k3 instead of designing one');
if ~ctl.start(varargin{:})
    return;
end
n = 4;
qw = ctl.list('q', n);
r = ctl.number('r');
if ~(r > 0) || any(qw < 0)
    ctl.usage_error('--r must be > 0 and the --q weights >= 0');
end
p = ctl.params;
a = p.l1 / 2;
k = p.m1 * a;
M0 = [p.m0 + p.m1, k; k, p.m1 * a^2 + p.I1];
A = [zeros(2), eye(2); -(M0 \ [0 0; 0 -k * p.g]), zeros(2)];
B = [zeros(2, 1); M0 \ [1; 0]];
h = ctl.scene.control_period;
E = expm([A B; zeros(1, n + 1)] * h);
Ad = E(1:n, 1:n);
Bd = E(1:n, n + 1);
switch ctl.get('gain')
    case 'discrete'
        [K, solver] = lagsim_dlqr(Ad, Bd, diag(qw) * h, r * h);
    case 'continuous'
        if exist('OCTAVE_VERSION', 'builtin') && isempty(which('lqr'))
            pkg('load', 'control');
        end
        K = lqr(A, B, diag(qw), r);
        solver = 'lqr';
    otherwise
        ctl.usage_error('--gain wants discrete or continuous');
end
ctl.say('cartpole_balance: %s LQR (h = %g s, %s): K = [%s]\n', ctl.get('gain'), h, solver, ...
        strjoin(arrayfun(@(v) sprintf('%.17g', v), K, 'UniformOutput', false), ', '));
if ~isempty(ctl.get('k'))
    K = ctl.list('k', n);
end
Acl = Ad - Bd * K;
if ~(max(abs(eig(Acl))) < 1)
    error('lagsim:design', 'cartpole_balance: this gain does not stabilize the sampled loop');
end

states = 0;
t_first = NaN;
t_last = NaN;
t_report = -Inf;
peak = [0 0];
max_u = 0;
x_end = [NaN NaN];
x_first = [];
st = ctl.next_state();
while ~isempty(st)
    idx = [ctl.joint(st, 'x'), ctl.joint(st, 'theta')];
    if all(idx > 0)
        x = [st.position(idx); st.velocity(idx)];
        u = 0;
        for j = 1:n
            u = u - K(j) * x(j);
        end
        ctl.command(st.sim_time, {'x'}, u);
        if states == 0
            t_first = st.sim_time;
            x_first = x;
        end
        states = states + 1;
        t_last = st.sim_time;
        peak = max(peak, abs(x(1:2)'));
        max_u = max(max_u, abs(u));
        x_end = x(1:2)';
        if ~ctl.quiet && st.sim_time - t_report >= 1
            t_report = st.sim_time;
            ctl.say('t=%8.3f  x=%+.5f  theta=%+.6f  F=%+.4f\n', st.sim_time, x(1), x(2), u);
        end
    end
    st = ctl.next_state();
end
pred = [0 0];
xl = x_first;
for s = 1:(states * ~isempty(x_first))
    pred = max(pred, abs(xl(1:2)'));
    xl = Acl * xl;
end
ctl.finish(sprintf(['states=%d t_first=%.6f t_last=%.6f max_abs_x=%.6g max_abs_theta=%.6g ' ...
    'max_abs_effort=%.6g end_x=%.3g end_theta=%.3g pred_max_abs_x=%.6g ' ...
    'pred_max_abs_theta=%.6g k_x=%.17g'], states, t_first, t_last, peak, max_u, x_end, pred, K(1)));
end
