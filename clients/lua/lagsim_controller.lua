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
local DESCRIBE_MS = 250 -- the pace of DESCRIBE while a scene is awaited (the C client's too)

function Controller.new(name, default_prefix, model, description)
  local self = setmetatable({ name = name, model = model, description = description or '',
                              opts = {}, order = {}, o = {}, dropped = 0, repeats = 0 }, Controller)
  self:option('prefix', default_prefix, 'channel prefix', 'string')
  self:option('url', '', "the plant's LCM URL, its lcm.url (default: LCM's default); commands go to the next port", 'string')
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

local function finite(v)
  if type(v) == 'number' then return v == v and v ~= math.huge and v ~= -math.huge end
  if type(v) == 'table' then
    for _, x in pairs(v) do if not finite(x) then return false end end
  end
  return true
end

-- The message of type T in `data`, or nil (counted in self.dropped). Like the C client it
-- keeps only a message that decodes whole: lcm-gen's decoder reads a string without its
-- NUL, or with bytes left over, as if nothing were wrong, so the message must encode back
-- to the very bytes that came; and every number in it must be finite.
function Controller:decode(T, data)
  local ok, m = pcall(T.decode, data)
  if ok then
    local oke, bytes = pcall(m.encode, m)
    if oke and bytes == data and finite(m) then return m end
  end
  self.dropped = self.dropped + 1
  return nil
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
  local state_url, command_url = lagsim_lcm.plant_urls(o.url ~= '' and o.url or nil)
  if not state_url then fail(self, 2, '--url: ' .. command_url) end
  self.lc = lagsim_lcm.new(state_url) -- states, status, events, scene
  self.lc_cmd = command_url ~= state_url and lagsim_lcm.new(command_url) or self.lc
  local ch = o.prefix .. '_'
  self.silent_ms = 0
  -- SIGINT, SIGTERM: the run ends (end=signal), with its summary, exit 0
  self.signalled = false
  lagsim_lcm.on_signals(function() self.signalled = true end)
  self.lc:subscribe(ch .. 'SCENE', function(_, data)
    self.silent_ms = 0
    local sc = self:decode(t.scene_t, data)
    if sc then
      self.scene = sc
      self.params = {}
      for k = 1, sc.num_params do self.params[sc.param_name[k]] = sc.param_value[k] end
    end
  end)
  self.lc:subscribe(ch .. 'STATE', function(_, data)
    self.silent_ms = 0
    self.state = self:decode(t.joint_state_t, data) or self.state
  end)
  self.lc:subscribe(ch .. 'STATUS', function() self.silent_ms = 0 end)
  -- the scene's reference, published just before each state with its sim_time
  self.lc:subscribe(ch .. 'REFERENCE', function(_, data)
    self.silent_ms = 0
    self.reference = self:decode(t.reference_t, data) or self.reference
  end)
  self.lc:subscribe(ch .. 'EVENT', function(_, data)
    self.silent_ms = 0
    local ev = self:decode(t.event_t, data)
    if ev and ev.kind == 'stop' then self.stopped = true end
  end)
  -- subscribed: from here on no state is missed (test harnesses wait for this line)
  print(string.format('%s: waiting for the scene description on %sSCENE', self.name, ch))
  io.stdout:flush()
  local waited, next_ask = 0, 0
  while not self.scene do
    if self.signalled then -- a run that ended before its scene came: no failure
      self.end_reason = 'signal'
      os.exit(self:finish('states=0'))
    end
    if waited >= o.timeout * 1000 then
      fail(self, 1, string.format('no scene on %sSCENE within %g s (is lagsimd running with this prefix?)',
                                  ch, o.timeout))
    end
    if waited >= next_ask then -- DESCRIBE every 0.25 s until the scene comes
      self:ask_scene()
      next_ask = next_ask + DESCRIBE_MS
    end
    if not self.lc:handle_timeout(WAIT_MS) then waited = waited + WAIT_MS end
  end
  if self.scene.model ~= self.model then
    fail(self, 1, string.format('prefix %s runs model %s, not %s', o.prefix, self.scene.model, self.model))
  end
  return o
end

function Controller:ask_scene()
  local req = self.t.control_t:new()
  req.request = self.t.control_t.DESCRIBE
  self.lc_cmd:publish(self.o.prefix .. '_CONTROL', req:encode())
end

-- st, or the newest state since, once the scene of its generation came (the daemon
-- publishes it just before the first state of a generation; DESCRIBE asks for it again
-- every 0.25 s, for when UDP lost it); nil when the run ended first. So the control law
-- never answers a state with another run's or scene's parameters (docs/clients.md).
local function with_scene(self, st)
  local o, next_ask, waited = self.o, 0, 0
  while st.generation ~= self.scene.generation do
    if self.signalled then self.end_reason = 'signal' return nil end
    if self.stopped then self.end_reason = 'stop' return nil end
    if self.silent_ms >= o.timeout * 1000 then self.end_reason = 'silence' return nil end
    if waited >= next_ask then
      self:ask_scene()
      next_ask = waited + DESCRIBE_MS
    end
    if not self.lc:handle_timeout(WAIT_MS) then
      self.silent_ms = self.silent_ms + WAIT_MS
      waited = waited + WAIT_MS
    end
    if self.state then st, self.state = self.state, nil end -- a newer state: that one
  end
  return st
end

-- Iterator over states: each newest state once, until the run ends. A copy of the state
-- answered last (same generation, step and sim time: the daemon published it again
-- because no answer reached it) is answered at once with the same command and not
-- returned: every state received is answered, the control law runs once per state (a law
-- run for every copy would cost a think time per copy and fall behind for good:
-- docs/clients.md, the rule). A state is returned only once self.scene (and self.params)
-- is the scene of its generation.
function Controller:states()
  local o = self.o
  local t_first
  return function()
    if self.end_reason then return nil end
    local st
    repeat
      while not self.state do
        if self.signalled then self.end_reason = 'signal' return nil end
        if self.stopped then self.end_reason = 'stop' return nil end
        if self.silent_ms >= o.timeout * 1000 then self.end_reason = 'silence' return nil end
        if not self.lc:handle_timeout(WAIT_MS) then self.silent_ms = self.silent_ms + WAIT_MS end
      end
      while self.lc:handle_timeout(0) do end -- drain what is queued: answer the newest
      st = self.state
      self.state = nil
      local last = self.last
      if last and st.generation == last.generation and st.step == last.step and
          st.sim_time == last.sim_time then
        self.lc_cmd:publish(o.prefix .. '_COMMAND', last.data)
        self.repeats = self.repeats + 1
        st = nil
      elseif st.generation ~= self.scene.generation then
        self.held = (self.held or 0) + 1
        st = with_scene(self, st)
        if not st then return nil end
      end
    until st
    self.current = st
    t_first = t_first or st.sim_time
    if o.duration > 0 and st.sim_time - t_first >= o.duration - 0.5 * self.scene.control_period then
      self.end_reason = 'duration' -- this state is still answered; the next call ends
    end
    return st
  end
end

function Controller:command(sim_time, names, efforts)
  local cmd = self.t.joint_command_t:new()
  cmd.utime = os.time() * 1000000 -- informational; Lua's clock has whole seconds
  cmd.sim_time = sim_time
  local st = self.current
  cmd.generation = st and st.generation or 0 -- of the state it answers (0: none yet)
  cmd.num_joints = #names
  cmd.name = names
  cmd.effort = {}
  for k = 1, #efforts do
    local u = efforts[k]
    if u ~= u or u == math.huge or u == -math.huge then u = 0.0 end -- never send NaN
    cmd.effort[k] = u
  end
  local data = cmd:encode()
  self.lc_cmd:publish(self.o.prefix .. '_COMMAND', data)
  if st and st.sim_time == sim_time then
    self.last = { generation = st.generation, step = st.step, sim_time = sim_time, data = data }
  end
  if self.trace and st and st.sim_time == sim_time then
    -- sim_time, positions, velocities, efforts sent: %.17g reads back to the same double
    local f = { string.format('%.17g', st.sim_time) }
    for k = 1, st.num_joints do f[#f + 1] = string.format('%.17g', st.position[k]) end
    for k = 1, st.num_joints do f[#f + 1] = string.format('%.17g', st.velocity[k]) end
    for k = 1, #cmd.effort do f[#f + 1] = string.format('%.17g', cmd.effort[k]) end
    self.trace:write(table.concat(f, ' '), '\n')
  end
end

function Controller:finish(summary)
  if self.trace then self.trace:close() end
  print(string.format('%s: summary end=%s %s dropped=%d repeats=%d', self.name,
                      tostring(self.end_reason), summary, self.dropped, self.repeats))
  io.stdout:flush()
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
