-- wrk: POST a fixed JSON body (the default rolling job, always a cache hit after the first).
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.body = "{}"
