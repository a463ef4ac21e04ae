-- A slow control law for a Lua controller run as written: lua5.2 think.lua SCRIPT ARGS...
-- Runs SCRIPT (its arguments after it) with every joint_command_t it constructs taking
-- LAGSIM_THINK_S wall seconds first (think.py says why the constructor), and a line
-- appended to the file LAGSIM_THINK_LOG (if set). Nothing else of the script changes.
-- LAGSIM_THINK_TYPES: a directory of the generated types (else LUA_PATH finds them).
local think = tonumber(os.getenv('LAGSIM_THINK_S') or '0')
local types = os.getenv('LAGSIM_THINK_TYPES')
if types then package.path = types .. '/?.lua;' .. types .. '/?/init.lua;' .. package.path end
local log = os.getenv('LAGSIM_THINK_LOG')
local T = require('lagsim.joint_command_t')
-- Lua 5.2 has no sleep of its own: an LCM instance on an in-process queue that nothing
-- publishes to waits its whole timeout. Not `os.execute('sleep')`: a shell and a sleep
-- process started for every answer take what the machine's load makes them (seen: a 0.15 s
-- law that took over a second beside a sanitizer build), and the law's time is no longer
-- the one the test chose.
local idle = require('lcm').lcm.new('memq://')
local new = T.new
T.new = function(...)
  if log then
    local f = io.open(log, 'a')
    f:write('law\n')
    f:close()
  end
  if think > 0 then idle:timedhandle(think) end
  return new(...)
end
local script, args = arg[1], {}
for i = 2, #arg do args[i - 1] = arg[i] end
args[0] = script
arg = args
dofile(script)
