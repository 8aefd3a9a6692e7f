-- wrk: POST rolling jobs that all differ (the load changes by a part in 1e9 per request),
dofile("loadtest/summary.lua")
-- so every request misses the cache and is solved. `-- OFFSET` keeps runs apart.
local counter = 0
local offset = 0

function init(args)
  offset = tonumber(args[1] or "0")
end

function request()
  counter = counter + 1
  local load = 1e-9 * (1 + (offset + counter) * 1e-9)
  local body = string.format('{"load": %.17g}', load)
  return wrk.format("POST", "/v1/rolling", {["Content-Type"] = "application/json"}, body)
end
