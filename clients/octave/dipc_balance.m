function dipc_balance(varargin)
%DIPC_BALANCE  Balances the double inverted pendulum on a cart (DIPC) upright with LQR,
%from MATLAB or GNU Octave.
%
%   dipc_balance --prefix DIPC --duration 20         % at the prompt, or from a shell:
%   octave --eval "dipc_balance --prefix DIPC -q"    % with <build>/octave on the path
%
%   The gain is designed here from the scene's parameters, the design of the C example
%   dipc_lqr:
%     1. linearize about upright (q = 0, qd = 0) from T and U (docs/models.md):
%          M0 qdd + G q = e0 u,  M0 = M(0), G = d2U/dq2 at 0 = diag(0, -(m1 l1/2 + m2 l1) g,
%          -m2 l2 g / 2), so A = [0 I; -M0\G 0], B = [0; M0\e0];
%     2. zero-order hold over the control period h (the daemon holds the effort over a
%        period): expm([A B; 0 0] h);
%     3. the discrete LQR with the Riemann sum of the continuous cost (Q h, R h):
%        lagsim_dlqr, i.e. dlqr of the Control System Toolbox (MATLAB) or of
%        octave-control (GNU Octave), else the DARE by doubling.
%   Weights default to Q = diag(5, 50, 50, 20, 700, 700), R = 1 (Bogdanov 2004). --k
%   applies a given gain instead (the cross-language check gives every language the same
%   numbers).
%
%   Answers every state with u = -K x on theta0, computed as 0 - k0 x0 - ... - k5 x5 in
%   that order (x = theta0, theta1, theta2 and their rates), so that it matches the other
%   languages bit for bit, until the daemon stops, falls silent for --timeout s, or
%   --duration s of sim time have passed; then prints a summary line (the keys of
%   dipc_lqr's). Options: those of lagsim_controller, --q, --r, --k.
ctl = lagsim_controller('dipc_balance', 'DIPC', 'dipc');
ctl.option('q', '5,50,50,20,700,700', 'state weights');
ctl.option('r', '1', 'input weight');
ctl.option('k', '', 'apply this gain k0,...,k5 instead of designing one');
if ~ctl.start(varargin{:})
    return;
end
n = 6;
qw = ctl.list('q', n);
r = ctl.number('r');
if ~(r > 0) || any(qw < 0)
    ctl.usage_error('--r must be > 0 and the --q weights >= 0');
end
h = ctl.scene.control_period;
[A, B] = linearize(ctl.params);
E = expm([A B; zeros(1, n + 1)] * h);
Ad = E(1:n, 1:n);
Bd = E(1:n, n + 1);
[K, solver] = lagsim_dlqr(Ad, Bd, diag(qw) * h, r * h);
ctl.say('dipc_balance: discrete LQR (h = %g s, %s): K = [%s]\n', h, solver, ...
        strjoin(arrayfun(@(v) sprintf('%.17g', v), K, 'UniformOutput', false), ', '));
if ~isempty(ctl.get('k'))
    K = ctl.list('k', n);
    ctl.say('dipc_balance: applying the given gain K = [%s]\n', ...
            strjoin(arrayfun(@(v) sprintf('%.17g', v), K, 'UniformOutput', false), ', '));
end
Acl = Ad - Bd * K;
if ~(max(abs(eig(Acl))) < 1)
    error('lagsim:design', 'dipc_balance: this gain does not stabilize the sampled loop');
end

names = {'theta0'};
states = 0;
t_first = NaN;
t_last = NaN;
t_report = -Inf;
peak = [0 0 0];
max_u = 0;
x_end = [NaN NaN NaN];
x_first = [];
st = ctl.next_state();
while ~isempty(st)
    idx = [ctl.joint(st, 'theta0'), ctl.joint(st, 'theta1'), ctl.joint(st, 'theta2')];
    if all(idx > 0)
        x = [st.position(idx); st.velocity(idx)];
        u = 0;
        for k = 1:n   % in this order, one product at a time: the other languages' sums
            u = u - K(k) * x(k);
        end
        ctl.command(st.sim_time, names, u);
        if states == 0
            t_first = st.sim_time;
            x_first = x;
        end
        states = states + 1;
        t_last = st.sim_time;
        peak = max(peak, abs(x(1:3)'));
        max_u = max(max_u, abs(u));
        x_end = x(1:3)';
        if ~ctl.quiet && st.sim_time - t_report >= 1
            t_report = st.sim_time;
            ctl.say('t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f\n', st.sim_time, x(1), ...
                    x(2), x(3), u);
        end
    end
    st = ctl.next_state();
end
% the linearized sampled loop x+ = (Ad - Bd K) x from the first state, as long
pred = [0 0 0];
xl = x_first;
for s = 1:(states * ~isempty(x_first))
    pred = max(pred, abs(xl(1:3)'));
    xl = Acl * xl;
end
ctl.finish(sprintf(['states=%d t_first=%.6f t_last=%.6f max_abs_theta0=%.6g ' ...
    'max_abs_theta1=%.6g max_abs_theta2=%.6g max_abs_effort=%.6g end_theta1=%.3g ' ...
    'end_theta2=%.3g pred_max_abs_theta0=%.6g pred_max_abs_theta1=%.6g ' ...
    'pred_max_abs_theta2=%.6g'], states, t_first, t_last, peak, max_u, x_end(2:3), pred));
end

function [A, B] = linearize(p)
% A and B of the DIPC about upright: M0 qdd + G q = e0 u (see above).
a = p.m1 * p.l1 / 2 + p.m2 * p.l1;
M0 = [p.m0 + p.m1 + p.m2, a, p.m2 * p.l2 / 2
      a, p.m1 * p.l1^2 / 4 + p.m2 * p.l1^2 + p.I1, p.m2 * p.l1 * p.l2 / 2
      p.m2 * p.l2 / 2, p.m2 * p.l1 * p.l2 / 2, p.m2 * p.l2^2 / 4 + p.I2];
G = diag([0, -a * p.g, -p.m2 * p.l2 * p.g / 2]);
A = [zeros(3), eye(3); -(M0 \ G), zeros(3)];
B = [zeros(3, 1); M0 \ [1; 0; 0]];
end
