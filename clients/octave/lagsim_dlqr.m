function [K, solver] = lagsim_dlqr(Ad, Bd, Q, R, solver)
%LAGSIM_DLQR  The discrete LQR gain K (u = -K x) of x+ = Ad x + Bd u with the cost
%sum of x'Qx + u'Ru, and which SOLVER gave it: 'dlqr' (the Control System Toolbox's in
%MATLAB, octave-control's in GNU Octave, loaded here with pkg load control) when there is
%one, else 'doubling': the DARE X = A'XA - A'XB (R + B'XB)^-1 B'XA + Q by the
%structure-preserving doubling algorithm (the Python, Lua and Java examples' solver), and
%K = (R + B'XB)^-1 B'XA. LAGSIM_DLQR(..., 'doubling') uses the doubling in any case.
if nargin < 5
    solver = '';
end
if ~strcmp(solver, 'doubling') && exist('OCTAVE_VERSION', 'builtin') && isempty(which('dlqr'))
    try
        pkg('load', 'control');
    catch
        % no octave-control: the doubling below
    end
end
if ~strcmp(solver, 'doubling') && ~isempty(which('dlqr'))
    K = dlqr(Ad, Bd, Q, R);
    solver = 'dlqr';
    return;
end
n = size(Ad, 1);
Ak = Ad;
Gk = Bd * (R \ Bd');
Hk = Q;
for it = 1:100
    W = eye(n) + Gk * Hk;
    An = Ak * (W \ Ak);
    Gn = Gk + Ak * (W \ (Gk * Ak'));
    Hn = Hk + Ak' * (Hk * (W \ Ak));
    done = max(abs(Hn(:) - Hk(:))) <= 1e-14 * max(abs(Hn(:)));
    Ak = An;
    Gk = Gn;
    Hk = Hn;
    if done
        break;
    end
end
if ~done
    error('lagsim:design', 'lagsim_dlqr: the Riccati doubling did not converge');
end
K = (R + Bd' * Hk * Bd) \ (Bd' * Hk * Ad);
solver = 'doubling';
end
