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

local DEFAULT_URL = 'udpm://239.255.76.67:7667?ttl=0' -- LCM's own default

-- The two LCM URLs of a lagsim plant whose lcm.url is `url` (nil or '': the environment's
-- LCM_DEFAULT_URL, else LCM's default): state_url, command_url. The daemon publishes
-- <PREFIX>_STATE, _STATUS, _EVENT and _SCENE on the state URL (the URL itself) and
-- listens for <PREFIX>_COMMAND and _CONTROL on the command URL: the same group and
-- options on the next port; memq:// is both. The C library's rule (lagsim_bus.h), checked
-- against the same cases (tests/net/plant_urls.txt). A URL a plant cannot have gives
-- nil and a message.
function M.plant_urls(url)
  if url == nil or url == '' then
    url = os.getenv('LCM_DEFAULT_URL')
    if url == nil or url == '' then url = DEFAULT_URL end
  end
  if #url >= 256 then return nil, 'LCM URL longer than 255 characters' end
  if url == 'memq://' then return url, url end
  local rest = url:match('^udpm://(.*)$')
  if not rest then
    return nil, "a lagsim plant speaks udpm://GROUP:PORT (or memq:// in one process), not '" .. url .. "'"
  end
  local addr, query = rest:match('^([^?]*)(.*)$')
  local group, port = '239.255.76.67', 7667
  if addr ~= '' then
    local a, b, c, d, p = addr:match('^(%d%d?%d?)%.(%d%d?%d?)%.(%d%d?%d?)%.(%d%d?%d?)(.*)$')
    if not a then
      return nil, "expected udpm://GROUP:PORT with GROUP a dotted IPv4 multicast address, got '" .. url .. "'"
    end
    local o = { tonumber(a), tonumber(b), tonumber(c), tonumber(d) }
    for k, txt in ipairs({ a, b, c, d }) do
      -- no leading zeros: LCM reads the group with inet_aton, which takes those as octal
      if o[k] > 255 or (#txt > 1 and txt:sub(1, 1) == '0') then
        return nil, "the group of '" .. url .. "' is not a multicast address written in decimal"
      end
    end
    if o[1] < 224 or o[1] > 239 then return nil, "the group of '" .. url .. "' is not a multicast address" end
    group = string.format('%d.%d.%d.%d', o[1], o[2], o[3], o[4])
    if p ~= '' then
      local ps = p:match('^:(%d%d?%d?%d?%d?)$')
      port = (ps and not (#ps > 1 and ps:sub(1, 1) == '0')) and tonumber(ps) or -1
      if port < 1 or port > 65534 then
        return nil, "expected a port from 1 to 65534 in '" .. url .. "' (commands go to the next port)"
      end
    end
  end
  return string.format('udpm://%s:%d%s', group, port, query),
         string.format('udpm://%s:%d%s', group, port + 1, query)
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
