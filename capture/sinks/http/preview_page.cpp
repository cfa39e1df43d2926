#include "capture/sinks/http/preview_page.h"

namespace arpipe {

// Relative URLs only, so the page works behind a reverse proxy's sub-path too. The state panel's
// element ids are what tests/e2e/http_preview_browser_test.cpp looks for.
std::string_view preview_page_html() {
  return R"html(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>arpiped live</title>
<style>
  body { margin: 0; font: 14px/1.4 system-ui, sans-serif; background: #111; color: #ddd; }
  header { padding: 6px 12px; background: #222; display: flex; gap: 16px; align-items: baseline; }
  header h1 { font-size: 16px; margin: 0; }
  #away { display: none; padding: 6px 12px; background: #a33; color: #fff; font-weight: bold; }
  main { display: flex; flex-wrap: wrap; gap: 12px; padding: 12px; }
  #view { flex: 1 1 640px; max-width: 100%; }
  #stream { width: 100%; height: auto; background: #000; display: block; }
  #state { flex: 0 1 360px; }
  table { border-collapse: collapse; width: 100%; }
  td { padding: 2px 6px; border-bottom: 1px solid #333; vertical-align: top; }
  td:first-child { color: #999; white-space: nowrap; }
  .tracking { color: #6d6; } .predicted { color: #dd6; } .lost { color: #e66; }
</style>
</head>
<body>
<header><h1>arpiped</h1><span id="source"></span><span id="updated"></span></header>
<div id="away">The camera is away: the stream shows a placeholder until it is back.</div>
<main>
  <div id="view"><img id="stream" src="stream.mjpg" alt="the composited stream"></div>
  <div id="state">
    <table>
      <tr><td>frame</td><td id="sequence">-</td></tr>
      <tr><td>tracking</td><td id="track_state">-</td></tr>
      <tr><td>pose (camera in world, m)</td><td id="pose">-</td></tr>
      <tr><td>light</td><td id="light">-</td></tr>
      <tr><td>blur</td><td id="blur">-</td></tr>
      <tr><td>frames/s</td><td id="fps">-</td></tr>
      <tr><td>latency to sinks (mean)</td><td id="latency">-</td></tr>
      <tr><td>drops</td><td id="drops">-</td></tr>
      <tr><td>stage timings</td><td id="stages">-</td></tr>
      <tr><td>sinks</td><td id="sinks">-</td></tr>
      <tr><td>stream clients</td><td id="clients">-</td></tr>
    </table>
  </div>
</main>
<script>
"use strict";
const $ = (id) => document.getElementById(id);
const fixed = (x, n) => (typeof x === "number" ? x.toFixed(n) : "-");
function show(s) {
  const f = s.frame || {};
  $("source").textContent = s.camera.source;
  $("away").style.display = s.camera.away ? "block" : "none";
  $("sequence").textContent = f.sequence !== undefined ? `${f.sequence} (index ${f.index})` : "-";
  const state = f.track_state || "-";
  $("track_state").textContent = state;
  $("track_state").className = state;
  const p = s.camera_position_world_m;
  $("pose").textContent = Array.isArray(p) ? p.map((v) => fixed(v, 3)).join(", ") : "-";
  const light = f.light || {};
  const first = (light.lights || [])[0];
  $("light").textContent = light.state ? `${light.state}${first ? " from " + first.direction_world.map((v) => fixed(v, 2)).join(", ") : ""}` : "fixed (config)";
  $("blur").textContent = f.blur ? `${f.blur.method} ${f.blur.samples || ""}` : "-";
  $("fps").textContent = fixed(s.pipeline.recent_fps, 1);
  $("latency").textContent = s.pipeline.latency_ms_mean !== null ? fixed(s.pipeline.latency_ms_mean, 1) + " ms" : "-";
  $("drops").textContent = `queue ${s.pipeline.queue_drops}, sequence gaps ${s.pipeline.sequence_gaps}`;
  $("stages").textContent = Object.entries(s.pipeline.stages).map(([k, v]) => `${k} ${fixed(v.mean_ms, 2)} ms`).join(", ");
  $("sinks").textContent = s.sinks.map((k) => `${k.key}: ${k.consumed} (${k.dropped} dropped)`).join(", ");
  $("clients").textContent = s.http.stream_clients;
  $("updated").textContent = "updated " + new Date().toLocaleTimeString();
}
async function poll() {
  try {
    const r = await fetch("state", { cache: "no-store" });
    if (r.ok) show(await r.json());
  } catch (e) {
    $("updated").textContent = "no answer from arpiped";
  }
  setTimeout(poll, 500);
}
poll();
</script>
</body>
</html>
)html";
}

}  // namespace arpipe
