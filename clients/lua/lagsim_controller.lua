--[[
lagsim_controller: what every Lua example controller shares (Lua 5.2): options, connect,
wait for the scene, answer states until the run ends, a summary line.

    local Controller = require('lagsim_controller')
    local ctl = Controller.new('manipulator_pd.lua', 'MANIPULATOR', 'manipulator')
    ctl:option('wn', 10, 'PD bandwidth, rad/s')       -- the example's own options
    ctl:start(arg)                                    -- parses, connects, waits for the scene
    for st in ctl:states() do                          -- each newest state once
      ctl:command(st.sim_time, {'q1', 'q2'}, {tau1, tau2})
    end
    ctl:finish('states=' .. n)                        -- "<name>: summary end=... states=..."

A run ends when the daemon publishes its `stop` event, when nothing came from the daemon
(no state, status or event) for --timeout s of waiting, or after --duration s of sim
time from the first state, or on SIGINT or SIGTERM (through Debian's lua-posix; without
it the signal ends the process); ctl.end_reason says which (stop, silence, duration,
signal; a signal while it waits for the scene prints the summary with states=0). Exit
status: 0 for these; 1 when no scene came within --timeout or it is another model's;
2 bad usage. Common options: --prefix, --url, --duration, --timeout, --types DIR (where
the lcm-gen Lua package `lagsim` is), --trace FILE (one line per answered state: sim time,
positions, velocities, efforts sent, each as %.17g), -q, --help.
]]
local lagsim_lcm = require('lagsim_lcm')

local Controller = {}
Controller.__index = Controller

local WAIT_MS = 50

function Controller.new(name, default_prefix, model, description)
  local self = setmetatable({ name = name, model = model, description = description or '',
                              opts = {}, order = {}, o = {}, dropped = 0, repeats = 0, held = 0 }, Controller)
  self:option('prefix', default_prefix, 'channel prefix', 'string')
  self:option('url', '', "the plant's LCM URL, its lcm.url (default: the URL a host's directory on LCM's default bus names for --prefix, else LCM's default); commands go to the next port", 'string')
  self:option('duration', 0, 'stop after S s of sim time from the first state (0: until the daemon stops)')
  self:option('timeout', 5, 'wall s without a scene, or without any message once running, before ending')
  self:option('types', '', 'directory holding the lcm-gen Lua package lagsim', 'string')
  self:option('trace', '', 'write each answered state and the efforts sent to this file', 'string')
  return self
end

-- kind: 'number' (default), 'string' or 'list' (comma-separated numbers)
function Controller:option(key, default, help, kind)
  self.opts[key] = { default = default, help = help, kind = kind or 'number' }
  table.insert(self.order, key)
  self.o[key] = default
end

-- A default as the user would type it: a list as 5,50,50 (tostring would print a
-- table's address); none (false or '') not shown
local function show_default(v)
  if type(v) == 'table' then
    local t = {}
    for i, x in ipairs(v) do t[i] = string.format('%.17g', x) end
    return ' (default ' .. table.concat(t, ',') .. ')'
  elseif v == false or v == nil or v == '' then
    return ''
  end
  return ' (default ' .. tostring(v) .. ')'
end

function Controller:usage(f)
  f:write(string.format('usage: lua5.2 %s [options]\n%s\n', self.name, self.description))
  for _, k in ipairs(self.order) do
    local op = self.opts[k]
    f:write(string.format('  --%-10s %s%s\n', k, op.help, show_default(op.default)))
  end
  f:write('  -q           quiet: summary only\n  --help       this text\n')
end

local function fail(self, code, msg)
  io.stderr:write(self.name .. ': ' .. msg .. '\n')
  os.exit(code)
end

function Controller:parse(argv)
  local i = 1
  while i <= #argv do
    local a = argv[i]
    if a == '--help' or a == '-h' then
      self:usage(io.stdout)
      os.exit(0)
    elseif a == '-q' then
      self.o.quiet = true
    else
      local key = a:match('^%-%-(.+)$')
      local op = key and self.opts[key]
      local v = argv[i + 1]
      if not op or v == nil then
        self:usage(io.stderr)
        fail(self, 2, "unknown or incomplete option '" .. a .. "'")
      end
      if op.kind == 'number' then
        local x = tonumber(v)
        if not x or x ~= x or x == math.huge or x == -math.huge then
          fail(self, 2, '--' .. key .. ' wants a number, not ' .. v)
        end
        self.o[key] = x
      elseif op.kind == 'list' then
        local t = {}
        for s in (v .. ','):gmatch('([^,]*),') do
          local x = tonumber(s)
          if not x or x ~= x or x == math.huge or x == -math.huge then
            fail(self, 2, '--' .. key .. ' wants comma-separated numbers, not ' .. v)
          end
          t[#t + 1] = x
        end
        self.o[key] = t
      else
        self.o[key] = v
      end
      i = i + 1
    end
    i = i + 1
  end
  if not (self.o.timeout > 0) or not (self.o.duration >= 0) then
    fail(self, 2, '--timeout must be > 0 and --duration >= 0')
  end
  return self.o
end

-- The protocol is the C client library's, through its Lua module (lagsim_lcm.client():
-- lagsim_client_lua.c): the URLs, finding the plant, DESCRIBE until the scene comes, each
-- state once with its copies answered, the scene rule, the generation on every command,
-- every message decoded whole and bounded. What is here: options, how a run ends, the
-- trace, the summary.

local function set_scene(self, sc)
  self.scene = sc
  self.params = {}
  for k = 1, sc.num_params do self.params[sc.param_name[k]] = sc.param_value[k] end
end

function Controller:start(argv)
  local o = self:parse(argv or {})
  if o.types ~= '' then
    package.path = o.types .. '/?.lua;' .. o.types .. '/?/init.lua;' .. package.path
  end
  local ok, t = pcall(require, 'lagsim')
  if not ok then
    fail(self, 2, "cannot load the lcm-gen Lua types 'lagsim': pass --types <build>/lua or set LUA_PATH")
  end
  self.t = t
  if o.trace ~= '' then
    self.trace = io.open(o.trace, 'w')
    if not self.trace then fail(self, 2, 'cannot write ' .. o.trace) end
  end
  local lc = lagsim_lcm.client()
  self.lib = lc
  local url = o.url ~= '' and o.url or nil
  local state_url, err = lc.plant_urls(url)
  if not state_url then fail(self, 2, '--url: ' .. err) end
  if not url then
    -- no --url: a host's directory on LCM's default bus may name the prefix's own URL
    -- (lag_client_locate, 1 s at most); else LCM's default (a plant there, or not yet)
    local where, found = lc.locate(o.prefix)
    if not where then fail(self, 2, '--prefix: ' .. found) end
    if where == 'host' then
      url = found
      print(string.format("%s: prefix %s runs on %s (the host's directory)", self.name, o.prefix, url))
      io.stdout:flush()
    end
  end
  local c, cerr = lc.new(o.prefix, url)
  if not c then fail(self, 1, cerr) end
  self.client = c
  -- SIGINT, SIGTERM: the run ends (end=signal), with its summary, exit 0
  self.signalled = false
  lagsim_lcm.on_signals(function() self.signalled = true end)
  -- subscribed: from here on no state is missed (test harnesses wait for this line)
  print(string.format('%s: waiting for the scene description on %s_SCENE', self.name, o.prefix))
  io.stdout:flush()
  local deadline = lc.now() + o.timeout
  while not self.scene do
    if self.signalled then -- a run that ended before its scene came: no failure
      self.end_reason = 'signal'
      os.exit(self:finish('states=0'))
    end
    local left = deadline - lc.now()
    if left <= 0 then
      fail(self, 1, string.format('no scene on %s_SCENE within %g s: %s', o.prefix, o.timeout,
                                  lc.plants_instead(url, o.prefix, 1.0)))
    end
    local sc = c:wait_scene(math.min(left, 0.25)) -- DESCRIBE every 0.25 s until it comes
    if sc then set_scene(self, sc) end
  end
  if self.scene.model ~= self.model then
    fail(self, 1, string.format('prefix %s runs model %s, not %s', o.prefix, self.scene.model, self.model))
  end
  return o
end

-- Messages from the daemon so far (kept or dropped): silence is when this stops growing.
-- Also keeps self.dropped, self.repeats, self.held: the library's counts.
local function heard(self, c)
  local k = c:counters()
  self.dropped, self.repeats, self.held = k.dropped, k.repeats, k.held
  return k.states + k.scenes + k.statuses + k.events + k.references + k.dropped + k.copies
end

-- Iterator over states: each newest state once, until the run ends. A copy of the state
-- answered last is answered by the library at once with the same command and not
-- returned: the control law runs once per state (docs/clients.md, the rule). A state is
-- returned only once self.scene (and self.params) is the scene of its generation (the
-- library holds it until that scene came).
function Controller:states()
  local o, c, lc = self.o, self.client, self.lib
  local t_first
  local last_heard, count = lc.now(), heard(self, c)
  return function()
    if self.end_reason then return nil end
    local st
    repeat
      if self.signalled then self.end_reason = 'signal' return nil end
      st = c:wait_state(WAIT_MS / 1000)
      local n = heard(self, c)
      if n ~= count then last_heard, count = lc.now(), n end
      if not st then
        if self.signalled then self.end_reason = 'signal' return nil end
        if c:stopped() then self.end_reason = 'stop' return nil end
        if lc.now() - last_heard > o.timeout then self.end_reason = 'silence' return nil end
      end
    until st
    if st.generation ~= self.scene.generation then set_scene(self, c:latest_scene()) end
    self.reference = c:latest_reference()
    self.current = st
    t_first = t_first or st.sim_time
    if o.duration > 0 and st.sim_time - t_first >= o.duration - 0.5 * self.scene.control_period then
      self.end_reason = 'duration' -- this state is still answered; the next call ends
    end
    return st
  end
end

function Controller:command(sim_time, names, efforts)
  local st = self.current
  local e = {}
  for k = 1, #efforts do
    local u = efforts[k]
    if u ~= u or u == math.huge or u == -math.huge then u = 0.0 end -- never send NaN
    e[k] = u
  end
  self.client:send_command(sim_time, names, e)
  if self.trace and st and st.sim_time == sim_time then
    -- sim_time, positions, velocities, efforts sent: %.17g reads back to the same double
    local f = { string.format('%.17g', st.sim_time) }
    for k = 1, st.num_joints do f[#f + 1] = string.format('%.17g', st.position[k]) end
    for k = 1, st.num_joints do f[#f + 1] = string.format('%.17g', st.velocity[k]) end
    for k = 1, #e do f[#f + 1] = string.format('%.17g', e[k]) end
    self.trace:write(table.concat(f, ' '), '\n')
  end
end

function Controller:finish(summary)
  if self.trace then self.trace:close() end
  if self.client then heard(self, self.client) end
  print(string.format('%s: summary end=%s %s dropped=%d repeats=%d', self.name,
                      tostring(self.end_reason), summary, self.dropped, self.repeats))
  io.stdout:flush()
  if self.client then self.client:close() end
  return 0
end

-- Index (1-based) of joint `name` in a state, or nil.
function Controller.joint(st, name)
  for k = 1, st.num_joints do
    if st.name[k] == name then return k end
  end
  return nil
end

return Controller
