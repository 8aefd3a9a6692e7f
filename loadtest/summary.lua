-- wrk: at the end of a run, one line `ok_rps total_rps p50_us p99_us non2xx` for run.sh.
-- Latency percentiles are over all responses (with a full pool, 429s included).
function done(summary, latency, requests)
  local seconds = summary.duration / 1e6
  local non2xx = summary.errors.status
  io.write(string.format("RESULT %.0f %.0f %.0f %.0f %d\n",
    (summary.requests - non2xx) / seconds, summary.requests / seconds,
    latency:percentile(50), latency:percentile(99), non2xx))
end
