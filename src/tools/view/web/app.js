// The page's client: speaks the Foxglove WebSocket protocol to rsg_view (the same one Foxglove
// and PlotJuggler use), subscribes to the JSON channels made for it, and feeds Chart.js.
"use strict";

const WINDOW = 300;  // points per plot
const JOINT_COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2"];
const XYZ_COLORS = ["#d62728", "#2ca02c", "#1f77b4"];

const $ = (id) => document.getElementById(id);
const charts = [];

function lineChart(id, names, colors, extra = {}) {
  if (typeof Chart === "undefined") return null;  // Chart.js missing: numbers only
  const chart = new Chart($(id), {
    type: "line",
    data: {labels: [], datasets: names.map((name, i) => ({label: name, data: [], borderColor: colors[i % colors.length],
                                                          borderWidth: 1.5, pointRadius: 0}))},
    options: {animation: false, responsive: true, maintainAspectRatio: false, normalized: true,
              scales: {x: {display: false}, ...(extra.scales || {})},
              plugins: {legend: {labels: {boxWidth: 10, font: {size: 10}}}}},
  });
  charts.push(chart);
  return chart;
}

const joints = [1, 2, 3, 4, 5, 6, 7].map((j) => `q${j}`);
const plots = {
  q: lineChart("plot-q", joints, JOINT_COLORS),
  dq: lineChart("plot-dq", joints.map((n) => "d" + n), JOINT_COLORS),
  tau: lineChart("plot-tau", [1, 2, 3, 4, 5, 6, 7].map((j) => `tau${j}`), JOINT_COLORS),
  ee: lineChart("plot-ee", ["x", "y", "z"], XYZ_COLORS),
  success: lineChart("plot-success", ["success rate"], ["#137333"], {scales: {y: {min: 0, max: 1}}}),
  rate: lineChart("plot-rate", ["rate [Hz]"], ["#1f77b4"]),
};

function push(chart, label, values) {
  if (!chart || !values) return;
  chart.data.labels.push(label);
  chart.data.datasets.forEach((set, i) => set.data.push(values[i]));
  if (chart.data.labels.length > WINDOW) {
    chart.data.labels.shift();
    chart.data.datasets.forEach((set) => set.data.shift());
  }
}

let dirty = false;
function redraw() {
  if (dirty) charts.forEach((chart) => chart.update("none"));
  dirty = false;
  requestAnimationFrame(redraw);
}
requestAnimationFrame(redraw);

function errorList(names) {
  if (names === null) return "–";
  if (names.length === 0) return '<span class="ok">none</span>';
  return '<ul class="errors">' + names.map((n) => `<li>${n}</li>`).join("") + "</ul>";
}

function onSummary(s) {
  $("samples").textContent = s.samples;
  $("robot-time").textContent = s.time ?? "–";
  $("dropped-all").textContent = s.dropped;
  $("robot-mode").textContent = s.robot_mode === null ? "–" : `${s.robot_mode_name ?? "?"} (${s.robot_mode})`;
  $("last-q").textContent = s.q === null ? "–" : s.q.map((v) => v.toFixed(4)).join(", ");
  $("current-errors").innerHTML = errorList(s.current_errors);
  $("last-motion-errors").innerHTML = errorList(s.last_motion_errors);
  const label = s.time ?? s.samples;
  push(plots.q, label, s.q);
  push(plots.dq, label, s.dq);
  push(plots.tau, label, s.tau_J);
  push(plots.ee, label, s.ee_position);
  push(plots.success, label, s.success_rate === null ? null : [s.success_rate]);
  dirty = true;
}

function onStatus(g) {
  $("link").innerHTML = g.link_up ? '<span class="ok">up</span>' : '<span class="bad">down</span>';
  $("source").textContent = g.source || "–";
  $("rate").textContent = Number(g.rate_hz).toFixed(1);
  $("received").textContent = g.frames_received;
  $("published").textContent = g.frames_published;
  $("lost").textContent = g.lost;
  $("duplicated").textContent = g.duplicated;
  $("reordered").textContent = g.reordered;
  $("out-of-sequence").textContent = g.out_of_sequence ?? "–";
  $("standard-dropped").textContent = g.standard_dropped ?? "–";
  const invalid = Object.entries(g.invalid || {}).filter(([, n]) => n > 0);
  $("invalid").textContent = invalid.length === 0 ? "0" : invalid.map(([k, n]) => `${k}=${n}`).join(" ");
  push(plots.rate, new Date().toLocaleTimeString(), [g.rate_hz]);
  dirty = true;
}

function connect() {
  const ws = new WebSocket(`ws://${location.host}/`, ["foxglove.websocket.v1"]);
  ws.binaryType = "arraybuffer";
  const handlers = new Map();  // subscription id -> handler
  const decoder = new TextDecoder();
  ws.onopen = () => { $("connection").textContent = "open"; };
  ws.onclose = () => { $("connection").textContent = "closed, retrying"; setTimeout(connect, 1000); };
  ws.onmessage = (event) => {
    if (typeof event.data === "string") {
      const message = JSON.parse(event.data);
      if (message.op === "advertise") {
        const subscriptions = [];
        for (const channel of message.channels) {
          const handler = channel.schemaName === "rsg.PageSummary" ? onSummary
                        : channel.schemaName === "rsg.GatewayStatus" ? onStatus : null;
          if (handler === null) continue;
          const id = handlers.size + 1;
          handlers.set(id, handler);
          subscriptions.push({id, channelId: channel.id});
        }
        ws.send(JSON.stringify({op: "subscribe", subscriptions}));
      } else if (message.op === "status" && message.id === "rsg_view.dropped") {
        const match = /dropped (\d+)/.exec(message.message);
        if (match) $("dropped").textContent = match[1];
      }
      return;
    }
    const view = new DataView(event.data);
    if (view.getUint8(0) !== 0x01) return;
    const handler = handlers.get(view.getUint32(1, true));
    if (handler) handler(JSON.parse(decoder.decode(new Uint8Array(event.data, 13))));
  };
}
connect();
