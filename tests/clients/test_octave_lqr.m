function test_octave_lqr()
%TEST_OCTAVE_LQR  lagsim_dlqr (clients/octave) by both of its solvers, dlqr and the
%doubling it falls back on where there is no dlqr (MATLAB without the Control System
%Toolbox), against closed forms: an error unless every check holds.
fails = 0;
% scalar x+ = a x + b u, cost q x^2 + r u^2: the DARE b^2 X^2 + (r - a^2 r - q b^2) X - q r = 0
% has one positive root, and K = a b X / (r + b^2 X)
a = 1.05;  b = 0.02;  q = 3;  r = 0.5;
c1 = r - a^2 * r - q * b^2;
X = (-c1 + sqrt(c1^2 + 4 * b^2 * q * r)) / (2 * b^2);
K = a * b * X / (r + b^2 * X);
for solver = {'', 'doubling'}
    [k, used] = lagsim_dlqr(a, b, q, r, solver{1});
    fails = fails + check(abs(k - K) <= 1e-12 * abs(K), ...
        sprintf('scalar by %s: K = %.17g, closed form %.17g', used, k, K));
end
% the double integrator held over h (ZOH), Q = I, R = 1: both solvers agree, and the
% doubling's X (K recomputed from it) leaves a DARE residual at round-off
h = 0.01;
Ad = [1 h; 0 1];
Bd = [h^2 / 2; h];
[k1, s1] = lagsim_dlqr(Ad, Bd, eye(2), 1);
[k2, s2] = lagsim_dlqr(Ad, Bd, eye(2), 1, 'doubling');
fails = fails + check(strcmp(s1, 'dlqr') && strcmp(s2, 'doubling'), ...
    sprintf('solvers used: %s, %s', s1, s2));
rel = max(abs(k1 - k2) ./ abs(k1));
fails = fails + check(rel <= 1e-9, sprintf('double integrator: dlqr and doubling within %.3g', rel));
fails = fails + check(max(abs(eig(Ad - Bd * k2))) < 1, 'the doubling gain stabilizes the loop');
fprintf('test_octave_lqr: %d failure(s)\n', fails);
if fails > 0
    error('test_octave_lqr: %d failure(s)', fails);
end
end

function f = check(ok, what)
if ok
    fprintf('ok  : %s\n', what);
    f = 0;
else
    fprintf('FAIL: %s\n', what);
    f = 1;
end
end
