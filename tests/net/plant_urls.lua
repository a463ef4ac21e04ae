-- plant_urls (clients/lua/lagsim_lcm.lua) against the cases every implementation passes
-- (tests/net/plant_urls.txt).
--     LUA_PATH=<build>/lua/?.lua;; lua5.2 plant_urls.lua TABLE
-- LCM_DEFAULT_URL must be unset (the ctest runs it so).
local lagsim_lcm = require('lagsim_lcm')
local fails, cases = 0, 0
assert(os.getenv('LCM_DEFAULT_URL') == nil or os.getenv('LCM_DEFAULT_URL') == '',
       'run with LCM_DEFAULT_URL unset')
for line in io.lines(arg[1]) do
  line = line:match('^%s*(.-)%s*$')
  if line ~= '' and line:sub(1, 1) ~= '#' then
    local base, want_state, want_cmd = line:match('^(.-) | (.-) | (.-)$')
    assert(base, 'bad table line: ' .. line)
    cases = cases + 1
    local s, c = lagsim_lcm.plant_urls(base ~= '(none)' and base or nil)
    if not s then s, c = 'ERROR', 'ERROR' end
    if s ~= want_state or c ~= want_cmd then
      print(string.format('FAIL: %q gives %s %s, expected %s %s', base, s, c, want_state, want_cmd))
      fails = fails + 1
    end
  end
end
print(string.format('plant_urls.lua: %d cases, %d failures', cases, fails))
os.exit((fails == 0 and cases >= 10) and 0 or 1)
