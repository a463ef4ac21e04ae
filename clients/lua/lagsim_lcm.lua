--[[
lagsim_lcm: LCM from Lua 5.2 through Debian's liblcm-lua, with one fix.

Debian's `lcm` module (liblcm-lua, for Lua 5.2 only: lua5.3 and later cannot load it) is
    local lc = require('lcm').lcm.new(url)   -- url nil: LCM's default (LCM_DEFAULT_URL)
    lc:publish(channel, data)                -- data: a string, e.g. msg:encode()
    local sub = lc:subscribe(regex, function(channel, data) ... end)
    lc:unsubscribe(sub)
    lc:handle()                              -- waits for one message, runs its handlers
    lc:handle_timeout(ms)                    -- true if one was handled, false on timeout
    lc:timedhandle(s)                        -- old form of handle_timeout (seconds)
(a signal that interrupts a wait raises an error there too; this wrapper's handle_timeout
returns false instead when the signal is one of M.on_signals', whose handler has run)
Channels are LCM's regular expressions (anchored). The raw module has one trap: an error
raised inside a handler unwinds through liblcm's C code and leaves the lcm_t unusable (the
next handle aborts the process). This wrapper has the same methods but runs each handler
under xpcall and raises its error, with the traceback, from the handle or handle_timeout
call that ran it:
    local lagsim_lcm = require('lagsim_lcm')
    local lc = lagsim_lcm.new()
A lagsim plant listens for commands on its own URL, the next port:
    local state_url, command_url = lagsim_lcm.plant_urls(url)  -- nil, message if refused
    local lc, lc_cmd = lagsim_lcm.new(state_url), lagsim_lcm.new(command_url)
]]
local lcm = require('lcm')

local M = {}
local LCM = {}
LCM.__index = LCM

-- The client library's Lua module (lagsim_client_lua.c: the protocol's rules, in C), loaded
-- once: from the path CMake wrote into <build>/lua/lagsim_client_path.lua (the build
-- tree's module, or the installed one), else by require('lagsim_client') through
-- package.cpath (LUA_CPATH). An error names every place tried.
local client_module
function M.client()
  if client_module then return client_module end
  local tried = {}
  local okp, path = pcall(require, 'lagsim_client_path')
  if okp and type(path) == 'string' then
    local open, err = package.loadlib(path, 'luaopen_lagsim_client')
    if open then client_module = open() end
    if not client_module then tried[#tried + 1] = path .. ' (lagsim_client_path.lua): ' .. tostring(err) end
  end
  if not client_module then
    local ok, m = pcall(require, 'lagsim_client')
    if ok then client_module = m else tried[#tried + 1] = "require('lagsim_client'): " .. tostring(m) end
  end
  if not client_module then
    error("cannot load lagsim's client module lagsim_client.so; tried " .. table.concat(tried, '; ')
          .. '. Set LUA_CPATH=<build>/lua/?.so;; or install lagsim', 0)
  end
  if client_module.abi ~= 1 then
    error(string.format('lagsim_client.so has ABI %d, not 1', client_module.abi), 0)
  end
  return client_module
end

-- The two LCM URLs of a lagsim plant whose lcm.url is `url` (nil or '': the environment's
-- LCM_DEFAULT_URL, else LCM's default): state_url, command_url. The daemon publishes
-- <PREFIX>_STATE, _STATUS, _EVENT and _SCENE on the state URL (the URL itself) and
-- listens for <PREFIX>_COMMAND and _CONTROL on the command URL: the same group and
-- options on the next port; memq:// is both. The C library's rule (lag_client_plant_urls,
-- through the client module), checked against tests/net/plant_urls.txt. A URL a plant
-- cannot have gives nil and a message.
function M.plant_urls(url)
  return M.client().plant_urls(url)
end

function M.new(url)
  return setmetatable({ lc = lcm.lcm.new(url), pending = nil }, LCM)
end

function LCM:subscribe(channel, handler)
  return self.lc:subscribe(channel, function(ch, data)
    if self.pending then return end -- an earlier handler failed: stop this dispatch
    local ok, err = xpcall(handler, debug.traceback, ch, data)
    if not ok then self.pending = err end
  end)
end

function LCM:unsubscribe(sub) self.lc:unsubscribe(sub) end

function LCM:publish(channel, data) self.lc:publish(channel, data) end

local function raise_pending(self)
  local e = self.pending
  if e then
    self.pending = nil
    error(e, 0)
  end
end

function LCM:handle()
  self.lc:handle()
  raise_pending(self)
end

-- Signals taken by M.on_signals: a wait that one of them interrupts is no error.
local signals = 0

-- Calls fn(signo) on SIGINT and SIGTERM instead of ending the process (lua-posix's
-- posix.signal; Debian's lua-posix). A handle_timeout that a signal interrupts returns
-- false, as on a timeout, the handler having run. false when lua-posix is absent.
function M.on_signals(fn)
  local ok, ps = pcall(require, 'posix.signal')
  if not ok then return false end
  for _, signo in ipairs({ ps.SIGINT, ps.SIGTERM }) do
    ps.signal(signo, function(s)
      signals = signals + 1
      fn(s)
    end)
  end
  return true
end

function LCM:handle_timeout(ms)
  local before = signals
  local ok, r = pcall(self.lc.handle_timeout, self.lc, math.floor(ms))
  if not ok then
    if signals == before then error(r, 0) end
    r = false -- liblcm-lua raises on EINTR: a signal ended the wait
  end
  raise_pending(self)
  return r
end

return M
