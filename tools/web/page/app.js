// undulate-web's page: draws the frames the server sends on its WebSocket
// (tools/web/frame.h describes them) with Chart.js, and sends the commands
// given here ("cmd ID ROBOT TEXT"; tools/web/req.h). Times are seconds since
// the server's first sample; every plot shows the last SPAN_S.
'use strict';
const SPAN_S = 30;
const PORTRAIT_S = 10;
const COLORS = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd'];
const state = { robots: new Map(), pairs: new Map(), now: 0, frames: 0, nextId: 1,
                ws: null, marks: [], bins: [] };
// The dashboard's token, from the URL undulate-web printed (#token=...): the
// fragment never leaves the browser in a request line. Offered at the
// handshake as the subprotocol "undulate-token.TOKEN" (tools/web/req.h).
const token = () => (/token=([A-Za-z0-9._~-]+)/.exec(location.hash) || [])[1];

function el(tag, attrs, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}
const num = (v, d) => (v === null || v === undefined) ? '-' : Number(v).toFixed(d);

function lineChart(canvas, datasets, yTitle, extra) {
  return new Chart(canvas, {
    type: 'line',
    data: { datasets },
    options: Object.assign({
      animation: false, parsing: false, normalized: true, responsive: true, maintainAspectRatio: false,
      spanGaps: false, elements: { point: { radius: 0 }, line: { borderWidth: 1.5 } },
      scales: { x: { type: 'linear', title: { display: true, text: 's' } },
                y: { title: { display: true, text: yTitle } } },
      plugins: { legend: { labels: { boxWidth: 10, font: { size: 10 } } } },
    }, extra || {}),
  });
}

// ---- robots -----------------------------------------------------------------
function robotCard(name) {
  const card = el('div', { class: 'card robot', id: 'robot-' + name });
  const info = el('div');
  info.append(el('h3', {}, name), el('div', { class: 'line' }), el('table', { class: 'status' }));
  // shown only while this page may command (body.commands, set by the server's hello)
  const row = el('div', { class: 'row cmd' });
  for (const m of ['limp', 'hold', 'sinusoid', 'oscillator']) {
    const b = el('button', { 'data-robot': name, 'data-mode': m }, m.toUpperCase());
    b.addEventListener('click', () => command(name, 'mode ' + m));
    row.append(b);
  }
  info.append(row);
  const a = el('div', { class: 'chartbox' }), p = el('div', { class: 'chartbox portrait' });
  const ca = el('canvas'), cp = el('canvas');
  a.append(ca); p.append(cp);
  card.append(info, a, p);
  document.getElementById('robots').append(card);
  const r = { name, card, t: [], a: [], w: [], angles: null, portrait: null, ca, cp };
  const opt = document.getElementById('p-robot');
  opt.append(el('option', { value: name }, name));
  return r;
}

function robotCharts(r, nj) {
  if (r.angles) return;
  const ds = [], pd = [];
  for (let j = 0; j < nj; j++) {
    ds.push({ label: 'joint ' + j, data: [], borderColor: COLORS[j % 4] });
    pd.push({ label: 'joint ' + j, data: [], borderColor: COLORS[j % 4], showLine: true });
  }
  r.angles = lineChart(r.ca, ds, 'angle (rad)');
  r.portrait = new Chart(r.cp, { type: 'scatter', data: { datasets: pd }, options: {
    animation: false, parsing: false, responsive: true, maintainAspectRatio: false,
    elements: { point: { radius: 0 }, line: { borderWidth: 1.2 } },
    scales: { x: { title: { display: true, text: 'angle (rad)' } }, y: { title: { display: true, text: 'speed (rad/s)' } } },
    plugins: { legend: { display: false }, title: { display: true, text: 'phase portrait (last 10 s)' } } } });
}

function robotStatus(s) {
  let r = state.robots.get(s.name);
  if (!r) { r = robotCard(s.name); state.robots.set(s.name, r); }
  const bus = s.bus === null ? 'no BUS yet' : 'bus ' + s.bus;
  const flags = [];
  if (s.stale) flags.push('STALE ' + num(s.age_s, 1) + ' s');
  if (s.silent_joints > 0) flags.push(s.silent_joints + ' joint(s) SILENT');
  if (s.fault) flags.push('fault: ' + s.fault);
  const line = r.card.querySelector('.line');
  line.textContent = `${s.mode} (${s.mode_reason}) · ${num(s.rate_hz, 1)} Hz loop · ${num(s.rx_hz, 0)} msg/s · ` +
    `${bus} · ${s.bus_errors} bus errors · ${s.timeouts} timeouts` + (flags.length ? ' · ' + flags.join(' · ') : '');
  line.className = 'line ' + (flags.length || s.bus === 'down' ? 'bad' : 'ok');
  r.card.dataset.mode = s.mode;
  const tb = r.card.querySelector('table');
  tb.replaceChildren(el('tr'));
  tb.firstChild.append(...['servo', '°C', 'V', 'error bits', 'status', 'torque'].map(h => el('th', {}, h)));
  for (const j of s.joints) {
    const tr = el('tr');
    tr.append(el('td', {}, j.id), el('td', {}, num(j.temperature, 0)), el('td', {}, num(j.voltage, 1)),
      el('td', {}, '0x' + (j.error_bits & 0xff).toString(16)), el('td', { class: j.status === 'ok' ? '' : 'bad' }, j.status),
      // torque as read back, the wanted one beside it when they differ (tools/top/model.c)
      el('td', { class: j.torque_differs ? 'bad' : '' }, j.torque_shown));
    tb.append(tr);
  }
  if (s.last_event) r.card.title = 'last event: ' + s.last_event;
}

function trim(arr, tmin) {
  let k = 0;
  while (k < arr.length && arr[k].x < tmin) k++;
  if (k) arr.splice(0, k);
}

function robotSamples(t, s) {
  let r = state.robots.get(s.name);
  if (!r) { r = robotCard(s.name); state.robots.set(s.name, r); }
  robotCharts(r, s.a.length);
  const ds = r.angles.data.datasets, pd = r.portrait.data.datasets;
  for (let j = 0; j < s.a.length && j < ds.length; j++) {
    for (let i = 0; i < t.length; i++) {
      ds[j].data.push({ x: t[i], y: s.a[j][i] === null ? NaN : s.a[j][i] });
      if (s.a[j][i] !== null && s.w[j][i] !== null) pd[j].data.push({ x: s.a[j][i], y: s.w[j][i], t: t[i] });
    }
  }
}

// ---- pairs ------------------------------------------------------------------
function pairCard(key, p) {
  const card = el('div', { class: 'card pair', id: 'pair-' + key.replace('|', '-') });
  card.append(el('div', {}, `${p.a} → ${p.b}: `), el('div', { class: 'chartbox' }));
  card.firstChild.append(el('span', { class: 'class' }, p.class));
  const c = el('canvas');
  card.lastChild.append(c);
  document.getElementById('pairs').append(card);
  const chart = lineChart(c, [
    { label: 'Δ', data: [], borderColor: '#1f77b4' },
    { label: '+2·asin(d̃)', data: [], borderColor: '#999', borderDash: [4, 3] },
    { label: '−2·asin(d̃)', data: [], borderColor: '#999', borderDash: [4, 3] },
  ], 'Δ (rad)', {});
  chart.options.scales.y.min = -Math.PI; chart.options.scales.y.max = Math.PI;
  return { card, chart, seen: state.frames };
}

function pairSamples(t, p) {
  const key = p.a + '|' + p.b;
  let q = state.pairs.get(key);
  if (!q) { q = pairCard(key, p); state.pairs.set(key, q); }
  q.seen = state.frames;
  q.card.querySelector('.class').textContent = 'end state: ' + p.class;
  q.card.dataset.class = p.class;
  const [d, up, lo] = q.chart.data.datasets;
  for (let i = 0; i < t.length; i++) {
    d.data.push({ x: t[i], y: p.d[i] === null ? NaN : p.d[i] });
    const b = p.bound[i] === null ? NaN : p.bound[i];
    up.data.push({ x: t[i], y: b });
    lo.data.push({ x: t[i], y: -b });
  }
}

// ---- simulator --------------------------------------------------------------
let simChart = null;
function simData(frame) {
  if (frame.status && frame.status.sim.present) document.getElementById('sim').hidden = false;
  if (!simChart && (frame.bins.t.length || (frame.status && frame.status.sim.present))) {
    simChart = lineChart(document.getElementById('simchart'), [
      { label: 'collisions per s', data: [], borderColor: '#d62728', yAxisID: 'y' },
      { label: 'contact force (N)', data: [], borderColor: '#1f77b4', yAxisID: 'y1' },
      { label: 'mode switch', data: [], borderColor: '#000', backgroundColor: '#000', showLine: false,
        pointRadius: 5, pointStyle: 'triangle', yAxisID: 'y' },
    ], 'collisions per s', {});
    simChart.options.scales.y1 = { position: 'right', title: { display: true, text: 'N' } };
  }
  if (!simChart) return;
  const [c, f, m] = simChart.data.datasets;
  for (let i = 0; i < frame.bins.t.length; i++) {
    const x = frame.bins.t[i] / 1000;
    c.data.push({ x, y: frame.bins.coll[i] });
    f.data.push({ x, y: frame.bins.force[i] === null ? NaN : frame.bins.force[i] });
  }
  for (const k of frame.marks) m.data.push({ x: k.t / 1000, y: 0, label: k.robot + ' → ' + k.mode });
}

// ---- commands ---------------------------------------------------------------
function command(robot, text) {
  if (!state.ws || state.ws.readyState !== 1) return answer({ kind: 'not-sent', robot, text: 'not connected' });
  const id = state.nextId++;
  state.ws.send(`cmd ${id} ${robot} ${text}`);
  answer({ id, kind: 'given', robot, text });
}

function answer(n) {
  const box = document.getElementById('answers');
  const line = el('div', { class: 'answer ' + n.kind, 'data-kind': n.kind, 'data-robot': n.robot || '' },
    `${new Date().toLocaleTimeString()} #${n.id || '-'} ${n.robot || ''} ${n.kind}: ${n.text}`);
  box.prepend(line);
  while (box.childNodes.length > 100) box.lastChild.remove();
}

// hello: "commands" (this page holds the token), "watch" (it does not) or
// "read-only" (the server sends no commands); "auth": a token taken later.
function note(n) {
  if (n.kind === 'hello' || n.kind === 'auth') {
    const commands = n.kind === 'auth' || n.text === 'commands';
    document.body.classList.toggle('commands', commands);
    document.getElementById('controls').hidden = !commands;
    document.getElementById('watching').hidden = commands || n.text === 'read-only';
    if (n.kind === 'hello') return;
  }
  answer(n);
}

// ---- frames -------------------------------------------------------------------
function onFrame(frame) {
  state.frames++;
  state.now = frame.now_ms / 1000;
  for (const n of frame.notes) note(n);
  if (frame.status) {
    for (const s of frame.status.robots) robotStatus(s);
    const st = frame.status;
    document.getElementById('summary').textContent = `${st.robots.length} robots · ` +
      (st.sim.present ? `simulator: ${st.sim.collisions_10s} collisions in 10 s, ${num(st.sim.impulse_10s, 3)} N·s` : 'no simulator') +
      ` · ${st.decode_errors} undecodable messages`;
    if (st.server) document.getElementById('server').textContent = 'server: ' +
      Object.entries(st.server).map(([k, v]) => `${k} ${v}`).join(' · ');
  }
  const t = frame.samples.t.map(ms => ms / 1000);
  for (const s of frame.samples.robots) robotSamples(t, s);
  for (const p of frame.pairs) pairSamples(t, p);
  for (const [key, q] of state.pairs)   // no longer neighbours
    if (q.seen !== state.frames) { q.chart.destroy(); q.card.remove(); state.pairs.delete(key); }
  simData(frame);
  document.body.dataset.frames = state.frames;
  scheduleRedraw();
}

// One redraw for however many frames arrived since the last: a browser short
// of CPU (a busy machine) takes the frames the server sends it, and redrawing
// after each one would queue work without end; the data is kept either way.
let redrawPending = false;
function scheduleRedraw() {
  if (redrawPending) return;
  redrawPending = true;
  setTimeout(() => { redrawPending = false; redraw(); }, 0);
}

function redraw() {
  const tmin = state.now - SPAN_S;
  // the axis starts at the first data (time 0) until the window is full:
  // an empty stretch before the run began tells nothing
  const fix = (chart) => { chart.options.scales.x.min = Math.max(0, tmin); chart.options.scales.x.max = state.now; };
  for (const r of state.robots.values()) {
    if (!r.angles) continue;
    for (const d of r.angles.data.datasets) trim(d.data, tmin);
    for (const d of r.portrait.data.datasets) {
      let k = 0;
      while (k < d.data.length && d.data[k].t < state.now - PORTRAIT_S) k++;
      if (k) d.data.splice(0, k);
    }
    // the portrait's axes from its points: Chart.js takes a line's x range from
    // its first and last points (it assumes them sorted), a cycle is not
    let ax = 0.1, aw = 0.1;
    for (const d of r.portrait.data.datasets)
      for (const p of d.data) { ax = Math.max(ax, Math.abs(p.x)); aw = Math.max(aw, Math.abs(p.y)); }
    Object.assign(r.portrait.options.scales.x, { min: -1.1 * ax, max: 1.1 * ax });
    Object.assign(r.portrait.options.scales.y, { min: -1.1 * aw, max: 1.1 * aw });
    fix(r.angles); r.angles.update('none'); r.portrait.update('none');
  }
  for (const q of state.pairs.values()) {
    for (const d of q.chart.data.datasets) trim(d.data, tmin);
    fix(q.chart); q.chart.update('none');
  }
  if (simChart) {
    const smin = state.now - 300;
    for (const d of simChart.data.datasets) trim(d.data, smin);
    simChart.options.scales.x.min = Math.max(0, smin); simChart.options.scales.x.max = state.now;
    simChart.update('none');
  }
}

function connect() {
  const t = token();
  const ws = new WebSocket(`ws://${location.host}/`, t ? ['undulate', 'undulate-token.' + t] : 'undulate');
  state.ws = ws;
  const conn = document.getElementById('conn');
  ws.onopen = () => { conn.textContent = 'live'; conn.className = 'ok'; };
  ws.onmessage = (ev) => { try { onFrame(JSON.parse(ev.data)); } catch (e) { console.error(e); } };
  ws.onclose = () => { conn.textContent = 'disconnected: reconnecting…'; conn.className = 'bad';
                       setTimeout(connect, 1000); };
}

document.getElementById('paramform').addEventListener('submit', (ev) => {
  ev.preventDefault();
  const v = (id) => document.getElementById(id).value.trim();
  const joint = v('p-joint');
  command(v('p-robot'), `param ${v('p-name')} ${v('p-value')}` + (joint === '' ? '' : ' ' + joint));
});
for (const b of document.querySelectorAll('#controls button[data-mode]'))
  b.addEventListener('click', () => command(b.dataset.robot, 'mode ' + b.dataset.mode));
// a token pasted into the address bar of an open page: connect again with it
window.addEventListener('hashchange', () => { if (state.ws) state.ws.close(); });
connect();
