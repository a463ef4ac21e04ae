--[[
The Lua LCM wrapper (clients/lua/lagsim_lcm.lua) over Debian's liblcm-lua, Lua 5.2.
In-process (memq://), no network:
  - subscribe() takes LCM's regular expressions ("RX_.*"), anchored ("RX_A" only RX_A);
  - an error in a handler is raised again, with its message, by the handle_timeout() or
    handle() call that ran it, and the LCM works afterwards (with the raw module the next
    handle aborts the process);
  - unsubscribe() stops delivery.
usage: lua5.2 test_lua_lcm.lua CLIENTS_LUA_DIR
]]
package.path = arg[1] .. '/?.lua;' .. package.path
local lc = require('lagsim_lcm').new('memq://')
local fails = 0
local function check(cond, what)
  print((cond and 'ok  : ' or 'FAIL: ') .. what)
  if not cond then fails = fails + 1 end
end
local function drain()
  local n = 0
  while lc:handle_timeout(0) do n = n + 1 end
  return n
end

local got, exact = {}, {}
local sub = lc:subscribe('RX_.*', function(ch, data) got[#got + 1] = ch .. '=' .. data end)
lc:subscribe('RX_A', function(ch) exact[#exact + 1] = ch end)
for _, ch in ipairs({ 'RX_A', 'RX_B', 'QX_A', 'RX_AB' }) do lc:publish(ch, ch) end
drain()
table.sort(got)
check(table.concat(got, ',') == 'RX_A=RX_A,RX_AB=RX_AB,RX_B=RX_B',
      "'RX_.*' receives RX_A, RX_AB, RX_B, not QX_A, payloads intact (" .. table.concat(got, ',') .. ')')
check(table.concat(exact, ',') == 'RX_A', "'RX_A' receives RX_A only (" .. table.concat(exact, ',') .. ')')

local bad = lc:subscribe('BAD', function(ch) error('handler failed on ' .. ch) end)
lc:publish('BAD', 'x')
local ok, err = pcall(function() return lc:handle_timeout(100) end)
check(not ok and tostring(err):find('handler failed on BAD', 1, true) ~= nil,
      'an error in a handler reaches the caller of handle_timeout() (' .. tostring(err):match('[^\n]*') .. ')')
lc:publish('BAD', 'x')
ok, err = pcall(function() return lc:handle() end)
check(not ok and tostring(err):find('handler failed on BAD', 1, true) ~= nil,
      'an error in a handler reaches the caller of handle()')
lc:unsubscribe(bad)
got = {}
lc:publish('RX_C', 'y')
lc:publish('BAD', 'x')
drain()
check(#got == 1 and got[1] == 'RX_C=y', 'after a failed handler the LCM keeps working')

lc:unsubscribe(sub)
got = {}
lc:publish('RX_D', 'z')
drain()
check(#got == 0, 'unsubscribe() stops delivery')
print(fails .. ' failure(s)')
os.exit(fails == 0 and 0 or 1)
