-- The conformance controller in Lua 5.2, over the Lua client library
-- (clients/lua/lagsim_controller.lua): the conformance law, for tests/protocol/play.py.
--
--   lua5.2 conformance.lua --types BUILD/lua --prefix P --url URL [--timeout S]
--
-- For each state the library hands it: u = -(kp q + kd qd) on each actuated joint of the
-- scene of that state's generation (kp, kd: the scene's parameters of those names), one
-- line "conformance: law generation=G sim_time=T" on stdout before the command goes
-- (docs/protocol.md, "Checking a binding of your own").
local here = arg[0]:match('^(.*)/[^/]*$') or '.'
package.path = here .. '/../../../clients/lua/?.lua;' .. package.path
local Controller = require('lagsim_controller')

local ctl = Controller.new('conformance.lua', 'CONFORMANCE', 'dipc')
ctl.o.timeout = 60
ctl:start(arg)
local laws = 0
for st in ctl:states() do
  local sc, kp, kd = ctl.scene, ctl.params.kp, ctl.params.kd
  local names, efforts = {}, {}
  for j = 1, sc.num_joints do
    if sc.actuated[j] then
      local i = Controller.joint(st, sc.joint_name[j])
      names[#names + 1] = sc.joint_name[j]
      efforts[#efforts + 1] = -(kp * st.position[i] + kd * st.velocity[i])
    end
  end
  laws = laws + 1
  print(string.format('conformance: law generation=%d sim_time=%.17g', st.generation, st.sim_time))
  io.stdout:flush()
  ctl:command(st.sim_time, names, efforts)
end
os.exit(ctl:finish(string.format('laws=%d held=%d', laws, ctl.held or 0)))
