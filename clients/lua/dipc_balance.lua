--[[
dipc_balance.lua: balances the double inverted pendulum on a cart upright with LQR, in
Lua 5.2. The same design as clients/python/dipc_balance.py (see there), line for line:
linearize about upright from T and U, zero-order hold over the control period, discrete
LQR with cost (Q h, R h) by Riccati doubling. --k applies a given gain instead.
    lua5.2 clients/lua/dipc_balance.lua --types build/lua [--prefix DIPC] [--k k0,...,k5]
Answers every state with u = 0 - k0 x0 - k1 x1 - ... - k5 x5 on theta0,
x = (theta0, theta1, theta2, theta0_dot, theta1_dot, theta2_dot), until the daemon stops,
falls silent for --timeout s, or --duration s of sim time have passed; then prints a
summary line.
]]
local here = (arg and arg[0] or ''):match('^(.*)/[^/]*$') or '.'
package.path = here .. '/?.lua;' .. package.path
local Controller = require('lagsim_controller')

local N = 6

local function zeros(r, c)
  local M = {}
  for i = 1, r do
    M[i] = {}
    for j = 1, c do M[i][j] = 0.0 end
  end
  return M
end

local function eye(n)
  local M = zeros(n, n)
  for i = 1, n do M[i][i] = 1.0 end
  return M
end

local function matmul(A, B)
  local C = zeros(#A, #B[1])
  for i = 1, #A do
    for j = 1, #B[1] do
      local s = 0
      for k = 1, #B do s = s + A[i][k] * B[k][j] end
      C[i][j] = s
    end
  end
  return C
end

local function transpose(A)
  local T = zeros(#A[1], #A)
  for i = 1, #A do
    for j = 1, #A[1] do T[j][i] = A[i][j] end
  end
  return T
end

local function add(A, B)
  local C = zeros(#A, #A[1])
  for i = 1, #A do
    for j = 1, #A[1] do C[i][j] = A[i][j] + B[i][j] end
  end
  return C
end

-- Gauss-Jordan with partial pivoting
local function inverse(A)
  local n = #A
  local M = {}
  for i = 1, n do
    M[i] = {}
    for j = 1, n do M[i][j] = A[i][j] end
    for j = 1, n do M[i][n + j] = (i == j) and 1.0 or 0.0 end
  end
  for c = 1, n do
    local p = c
    for r = c + 1, n do
      if math.abs(M[r][c]) > math.abs(M[p][c]) then p = r end
    end
    if M[p][c] == 0.0 then error('singular matrix') end
    M[c], M[p] = M[p], M[c]
    local piv = M[c][c]
    for j = 1, 2 * n do M[c][j] = M[c][j] / piv end
    for r = 1, n do
      if r ~= c and M[r][c] ~= 0.0 then
        local f = M[r][c]
        for j = 1, 2 * n do M[r][j] = M[r][j] - f * M[c][j] end
      end
    end
  end
  local R = zeros(n, n)
  for i = 1, n do
    for j = 1, n do R[i][j] = M[i][n + j] end
  end
  return R
end

-- exp(A): scaling so that ||A||_1 / 2^s <= 0.5, Taylor to order 20, s squarings
local function expm(A)
  local n = #A
  local norm = 0
  for j = 1, n do
    local s = 0
    for i = 1, n do s = s + math.abs(A[i][j]) end
    norm = math.max(norm, s)
  end
  local s = 0
  while norm > 0.5 do
    norm = norm / 2.0
    s = s + 1
  end
  local As = zeros(n, n)
  for i = 1, n do
    for j = 1, n do As[i][j] = A[i][j] / 2.0 ^ s end
  end
  local E, T = eye(n), eye(n)
  for k = 1, 20 do
    T = matmul(T, As)
    for i = 1, n do
      for j = 1, n do T[i][j] = T[i][j] / k end
    end
    E = add(E, T)
  end
  for _ = 1, s do E = matmul(E, E) end
  return E
end

local function linearize(p)
  local m0, m1, m2, l1, l2, I1, I2, g = p.m0, p.m1, p.m2, p.l1, p.l2, p.I1, p.I2, p.g
  local a = m1 * l1 / 2 + m2 * l1
  local M0 = { { m0 + m1 + m2, a, m2 * l2 / 2 },
               { a, m1 * l1 * l1 / 4 + m2 * l1 * l1 + I1, m2 * l1 * l2 / 2 },
               { m2 * l2 / 2, m2 * l1 * l2 / 2, m2 * l2 * l2 / 4 + I2 } }
  local G = { 0.0, -a * g, -m2 * l2 * g / 2 }
  local Mi = inverse(M0)
  local A, B = zeros(N, N), zeros(N, 1)
  for i = 1, 3 do
    A[i][3 + i] = 1.0
    for j = 1, 3 do A[3 + i][j] = -Mi[i][j] * G[j] end
    B[3 + i][1] = Mi[i][1]
  end
  return A, B
end

local function c2d(A, B, h)
  local Z = zeros(N + 1, N + 1)
  for i = 1, N do
    for j = 1, N do Z[i][j] = A[i][j] * h end
    Z[i][N + 1] = B[i][1] * h
  end
  local E = expm(Z)
  local Ad, Bd = zeros(N, N), zeros(N, 1)
  for i = 1, N do
    for j = 1, N do Ad[i][j] = E[i][j] end
    Bd[i][1] = E[i][N + 1]
  end
  return Ad, Bd
end

local function dare(A, B, Q, R)
  local Ak, Gk, Hk = A, zeros(N, N), Q
  for i = 1, N do
    for j = 1, N do Gk[i][j] = B[i][1] * B[j][1] / R end
  end
  for _ = 1, 100 do
    local W = add(eye(N), matmul(Gk, Hk))
    W = inverse(W)
    local AW = matmul(Ak, W)
    local An = matmul(AW, Ak)
    local Gn = add(Gk, matmul(matmul(AW, Gk), transpose(Ak)))
    local Hn = add(Hk, matmul(matmul(transpose(Ak), Hk), matmul(W, Ak)))
    local diff, size = 0, 0
    for i = 1, N do
      for j = 1, N do
        diff = math.max(diff, math.abs(Hn[i][j] - Hk[i][j]))
        size = math.max(size, math.abs(Hn[i][j]))
      end
    end
    Ak, Gk, Hk = An, Gn, Hn
    if diff <= 1e-14 * size then return Hk end
  end
  error('the Riccati doubling did not converge')
end

local function design(p, h, qw, r)
  local A, B = linearize(p)
  local Ad, Bd = c2d(A, B, h)
  local Qd = zeros(N, N)
  for i = 1, N do Qd[i][i] = qw[i] * h end
  local X = dare(Ad, Bd, Qd, r * h)
  local XB = matmul(X, Bd)
  local den = r * h
  for i = 1, N do den = den + Bd[i][1] * XB[i][1] end
  local KA = matmul(transpose(XB), Ad)[1]
  local K = {}
  for i = 1, N do K[i] = KA[i] / den end
  return Ad, Bd, K
end

local function closed_loop(Ad, Bd, K)
  local P = zeros(N, N)
  for i = 1, N do
    for j = 1, N do P[i][j] = Ad[i][j] - Bd[i][1] * K[j] end
  end
  return P
end

local function fmt_list(v)
  local t = {}
  for i = 1, #v do t[i] = string.format('%.17g', v[i]) end
  return table.concat(t, ', ')
end

local ctl = Controller.new('dipc_balance.lua', 'DIPC', 'dipc',
                           'Balances the DIPC upright with a discrete LQR gain designed from the scene.')
ctl:option('q', { 5, 50, 50, 20, 700, 700 }, 'state weights', 'list')
ctl:option('r', 1, 'input weight')
ctl:option('k', false, 'apply this gain k0,...,k5 instead of designing one', 'list')
local o = ctl:start(arg)
if #o.q ~= N or not (o.r > 0) then
  io.stderr:write('dipc_balance.lua: --q wants 6 weights >= 0, --r a number > 0\n')
  os.exit(2)
end
for i = 1, N do
  if not (o.q[i] >= 0) then
    io.stderr:write('dipc_balance.lua: --q wants 6 weights >= 0\n')
    os.exit(2)
  end
end
local h = ctl.scene.control_period
local Ad, Bd, K = design(ctl.params, h, o.q, o.r)
print(string.format('dipc_balance.lua: discrete LQR (h = %g s): K = [%s]', h, fmt_list(K)))
if o.k then
  if #o.k ~= N then
    io.stderr:write('dipc_balance.lua: --k wants 6 numbers\n')
    os.exit(2)
  end
  K = o.k
  print('dipc_balance.lua: applying the given gain K = [' .. fmt_list(K) .. ']')
end
io.stdout:flush()
-- the sampled closed loop must be stable: powers of Ad - Bd K must shrink
local P = closed_loop(Ad, Bd, K)
for _ = 1, 12 do P = matmul(P, P) end -- P^4096
local pmax = 0
for i = 1, N do
  for j = 1, N do pmax = math.max(pmax, math.abs(P[i][j])) end
end
if not (pmax < 1e-3) then
  io.stderr:write('dipc_balance.lua: this gain does not stabilize the sampled loop\n')
  os.exit(1)
end

local names = { 'theta0' }
local states = 0
local t_first, t_last, t_report = 0 / 0, 0 / 0, -math.huge
local peak, max_u, x_end, x_first = { 0, 0, 0 }, 0, { 0 / 0, 0 / 0, 0 / 0 }, nil
for st in ctl:states() do
  local idx = { Controller.joint(st, 'theta0'), Controller.joint(st, 'theta1'),
                Controller.joint(st, 'theta2') }
  if idx[1] and idx[2] and idx[3] then
    local x = {}
    for k = 1, 3 do
      x[k] = st.position[idx[k]]
      x[3 + k] = st.velocity[idx[k]]
    end
    local u = 0.0
    for k = 1, N do u = u - K[k] * x[k] end
    ctl:command(st.sim_time, names, { u })

    if states == 0 then
      t_first = st.sim_time
      x_first = x
    end
    states = states + 1
    t_last = st.sim_time
    for k = 1, 3 do peak[k] = math.max(peak[k], math.abs(x[k])) end
    max_u = math.max(max_u, math.abs(u))
    x_end = x
    if not o.quiet and st.sim_time - t_report >= 1.0 then
      t_report = st.sim_time
      print(string.format('t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f', st.sim_time, x[1], x[2],
                          x[3], u))
      io.stdout:flush()
    end
  end
end
-- the linearized sampled loop x+ = (Ad - Bd K) x from the first state, as long
local pred = { 0, 0, 0 }
if x_first then
  local Acl = closed_loop(Ad, Bd, K)
  local xl = x_first
  for _ = 1, states do
    for k = 1, 3 do pred[k] = math.max(pred[k], math.abs(xl[k])) end
    local xn = {}
    for i = 1, N do
      local s = 0
      for j = 1, N do s = s + Acl[i][j] * xl[j] end
      xn[i] = s
    end
    xl = xn
  end
end
os.exit(ctl:finish(string.format(
  'states=%d t_first=%.6f t_last=%.6f max_abs_theta0=%.6g max_abs_theta1=%.6g max_abs_theta2=%.6g '
    .. 'max_abs_effort=%.6g end_theta1=%.3g end_theta2=%.3g pred_max_abs_theta0=%.6g '
    .. 'pred_max_abs_theta1=%.6g pred_max_abs_theta2=%.6g',
  states, t_first, t_last, peak[1], peak[2], peak[3], max_u, x_end[2], x_end[3], pred[1], pred[2],
  pred[3])))
