-- wrk: POST the default rolling job, always the same body: a cache hit after the first.
dofile("loadtest/summary.lua")
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.body = "{}"
