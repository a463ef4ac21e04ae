--[[
manipulator_pd.lua: the manipulator tracks the scene's reference, in Lua 5.2: the
reference_t on <PREFIX>_REFERENCE, published just before each state (q_d = r, qd_d = r',
qdd_d = r'', the exact second derivative; a joint without a reference holds its first
position), as manipulator_pd in C does, with PD plus computed-torque feedforward from the
scene's parameters:
    tau = M(q) (qdd_d + Kp e + Kd e_dot) + C(q, qd) qd + g(q),  Kp = wn^2, Kd = 2 wn,
M, C and g in closed form from the model's T and U (docs/models.md), written exactly as
in clients/python/manipulator_pd.py and the C core (same operations in the same order,
the same libm), so that Lua, Python, C and C++ give bit-identical runs.
    lua5.2 clients/lua/manipulator_pd.lua --types build/lua [--prefix MANIPULATOR] ...
Answers every state with a command carrying that state's sim_time (lockstep-safe), until
the daemon stops, falls silent for --timeout s, or --duration s of sim time have passed;
then prints a summary line.
]]
local here = (arg and arg[0] or ''):match('^(.*)/[^/]*$') or '.'
package.path = here .. '/?.lua;' .. package.path
local Controller = require('lagsim_controller')

-- q_d, qd_d, qdd_d at a state from the latest reference (manipulator_pd.c's rule)
local des = { stale = 0, have = { false, false } }
local function desired(ref, st, q)
  if not des.hold then des.hold = { q[1], q[2] } end
  if ref and ref.sim_time ~= st.sim_time then des.stale = des.stale + 1 end
  local qdes, qddes, qdd = { des.hold[1], des.hold[2] }, { 0.0, 0.0 }, { 0.0, 0.0 }
  for k, name in ipairs({ 'q1', 'q2' }) do
    local j = ref and Controller.joint(ref, name)
    des.have[k] = j ~= nil
    if j then qdes[k], qddes[k], qdd[k] = ref.r[j], ref.rdot[j], ref.rddot[j] end
  end
  return qdes, qddes, qdd
end

-- tau = M(q) v + C(q, qd) qd + g(q) (closed form, see above)
local function computed_torque(p, q, qd, v)
  local m1, m2, l1, I1, I2, g = p.m1, p.m2, p.l1, p.I1, p.I2, p.g
  local s, c, a = math.sin(q[1]), math.cos(q[1]), m2 * q[2]
  local M = { m1 * l1 * l1 + I1 + I2 + m2 * q[2] * q[2], 0.0, 0.0, m2 }
  local h = { 2.0 * a * qd[1] * qd[2] + (m1 * l1 + a) * g * c, -a * qd[1] * qd[1] + m2 * g * s }
  local tau1 = M[1] * v[1] + M[2] * v[2] + h[1]
  local tau2 = M[3] * v[1] + M[4] * v[2] + h[2]
  return { tau1, tau2 }
end

local ctl = Controller.new('manipulator_pd.lua', 'MANIPULATOR', 'manipulator',
                           'Tracks the scene\'s reference (<PREFIX>_REFERENCE) with PD + computed torque.')
ctl:option('wn', 10, 'PD bandwidth, rad/s: Kp = wn^2, Kd = 2 wn')
ctl:option('settle', 2, 'error statistics skip the first S s')
local o = ctl:start(arg)
if not (o.wn > 0) or not (o.settle >= 0) then
  io.stderr:write('manipulator_pd.lua: --wn must be > 0, --settle >= 0\n')
  os.exit(2)
end
local p = ctl.params
for _, k in ipairs({ 'm1', 'm2', 'l1', 'I1', 'I2', 'g' }) do
  if not p[k] then
    io.stderr:write('manipulator_pd.lua: the scene lacks parameter ' .. k .. '\n')
    os.exit(1)
  end
end
local kp, kd = o.wn * o.wn, 2.0 * o.wn
if not o.quiet then
  print(string.format('manipulator_pd.lua: scene on %s_*: mode %s, control period %g s; Kp %g, Kd %g',
                      o.prefix, ctl.scene.mode, ctl.scene.control_period, kp, kd))
end

local names = { 'q1', 'q2' }
local states, n_settled = 0, 0
local t_first, t_last, t_report = 0 / 0, 0 / 0, -math.huge
local emax, esq, emax_all = { 0, 0 }, { 0, 0 }, { 0, 0 }
for st in ctl:states() do
  local i1, i2 = Controller.joint(st, 'q1'), Controller.joint(st, 'q2')
  if i1 and i2 then
    local q = { st.position[i1], st.position[i2] }
    local qd = { st.velocity[i1], st.velocity[i2] }
    local qdes, qddes, qdddes = desired(ctl.reference, st, q)
    if states == 0 and not o.quiet then
      print(string.format('manipulator_pd.lua: tracking q1 %s, q2 %s',
                          des.have[1] and 'its reference' or 'its first position',
                          des.have[2] and 'its reference' or 'its first position'))
    end
    local v = {}
    for k = 1, 2 do
      v[k] = qdddes[k] + kp * (qdes[k] - q[k]) + kd * (qddes[k] - qd[k])
    end
    local tau = computed_torque(p, q, qd, v)
    ctl:command(st.sim_time, names, tau)

    if states == 0 then t_first = st.sim_time end
    states = states + 1
    t_last = st.sim_time
    local e = { qdes[1] - q[1], qdes[2] - q[2] }
    for k = 1, 2 do emax_all[k] = math.max(emax_all[k], math.abs(e[k])) end
    if st.sim_time - t_first >= o.settle then
      n_settled = n_settled + 1
      for k = 1, 2 do
        emax[k] = math.max(emax[k], math.abs(e[k]))
        esq[k] = esq[k] + e[k] * e[k]
      end
    end
    if not o.quiet and st.sim_time - t_report >= 1.0 then
      t_report = st.sim_time
      print(string.format('t=%8.3f  q1=%+.5f (e %+.2e)  q2=%+.5f (e %+.2e)  tau=%+.3f %+.3f',
                          st.sim_time, q[1], e[1], q[2], e[2], tau[1], tau[2]))
      io.stdout:flush()
    end
  end
end
local rms = { 0 / 0, 0 / 0 }
for k = 1, 2 do
  if n_settled > 0 then rms[k] = math.sqrt(esq[k] / n_settled) end
end
os.exit(ctl:finish(string.format(
  'states=%d t_first=%.6f t_last=%.6f settle=%g max_abs_e1=%.6g max_abs_e2=%.6g rms_e1=%.6g '
    .. 'rms_e2=%.6g max_abs_e1_all=%.6g max_abs_e2_all=%.6g references_stale=%d',
  states, t_first, t_last, o.settle, emax[1], emax[2], rms[1], rms[2], emax_all[1], emax_all[2],
  des.stale)))
