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
Channels are LCM's regular expressions (anchored). The raw module has one trap: an error
raised inside a handler unwinds through liblcm's C code and leaves the lcm_t unusable (the
next handle aborts the process). This wrapper has the same methods but runs each handler
under xpcall and raises its error, with the traceback, from the handle or handle_timeout
call that ran it:
    local lagsim_lcm = require('lagsim_lcm')
    local lc = lagsim_lcm.new()
]]
local lcm = require('lcm')

local M = {}
local LCM = {}
LCM.__index = LCM

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

function LCM:handle_timeout(ms)
  local r = self.lc:handle_timeout(math.floor(ms))
  raise_pending(self)
  return r
end

return M
