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

// ---- the world from above -----------------------------------------------------
// The simulator's world as the frames carry it (frame.h, "world"): in the
// plane each robot's links as thick segments in its colour and its name at its
// head, the wall segments; on the row each robot's contact body as a disc on
// the line between the walls. Contacts are marks at their point, fading over
// FADE_S: filled red for an impact, a black ring for resting contact, the area
// growing with the pair's mean force. Whatever the network sent, a number that
// is not finite is not drawn.
const FADE_S = 1.2;
const MAX_MARKS = 4000;           // marks kept (the server sends each once)
const WORLD_W = 780;              // CSS pixels
const ROBOT_COLORS = ['#1f77b4', '#ff7f0e', '#2ca02c', '#9467bd', '#8c564b', '#e377c2', '#17becf',
                      '#bcbd22', '#393b79', '#637939'];
const world = { last: null, kind: null, box: null, marks: [], colors: new Map(), simPresent: true, drawn: [] };
const fin = (v) => typeof v === 'number' && Number.isFinite(v);

// a robot keeps its colour for the page's life (worldData gives them out)
function robotColor(name) {
  let c = world.colors.get(name);
  if (!c) {
    const n = world.colors.size;
    c = n < ROBOT_COLORS.length ? ROBOT_COLORS[n] : `hsl(${Math.round(n * 137.5) % 360}, 60%, 40%)`;
    world.colors.set(name, c);
  }
  return c;
}

const isLink = (l) => Array.isArray(l) && l.length >= 5 && l.every(fin) && l[3] > 0 && l[4] > 0;
const linkEnds = (l) => {
  const dx = Math.cos(l[2]) * l[3] / 2, dy = Math.sin(l[2]) * l[3] / 2;
  return [[l[0] - dx, l[1] - dy], [l[0] + dx, l[1] + dy]];   // rear, front
};

function worldData(w) {
  if (!w || typeof w !== 'object' || !Array.isArray(w.robots)) return;
  if (w.kind !== world.kind) { world.kind = w.kind; world.box = null; }
  world.last = w;
  const c = w.contacts || {};
  const n = Array.isArray(c.t) ? c.t.length : 0;
  for (let i = 0; i < n; i++) {
    if (!fin(c.t[i]) || !fin(c.x[i]) || !fin(c.y[i])) continue;
    world.marks.push({ t: c.t[i] / 1000, a: c.a[i], b: c.b[i], x: c.x[i], y: c.y[i],
                       f: fin(c.f[i]) && c.f[i] > 0 ? c.f[i] : 0, impact: c.impact[i] === 1 });
  }
  if (world.marks.length > MAX_MARKS) world.marks.splice(0, world.marks.length - MAX_MARKS);
  // colours in the order the robots stand, left to right, when first seen
  const seen = w.robots.filter(r => !world.colors.has(r.name) && ((r.links || []).some(isLink) || fin(r.lateral)));
  const at = (r) => fin(r.neutral) ? r.neutral : fin(r.lateral) ? r.lateral : 0;
  seen.sort((p, q) => at(p) - at(q)).forEach(r => robotColor(r.name));
  document.getElementById('world').hidden = false;
  document.getElementById('world-kind').textContent = w.kind === 'plane' ? '(the plane)' : '(the row)';
}

// What the view must hold: walls and robots as seen so far (it only grows, so
// closing walls are seen moving, not the view zooming with them).
function worldExtent(w) {
  const b = { x0: Infinity, x1: -Infinity, y0: Infinity, y1: -Infinity };
  const add = (x, y) => {
    if (!fin(x) || !fin(y)) return;
    b.x0 = Math.min(b.x0, x); b.x1 = Math.max(b.x1, x); b.y0 = Math.min(b.y0, y); b.y1 = Math.max(b.y1, y);
  };
  add(w.wall_left, 0); add(w.wall_right, 0);
  for (const s of w.walls || []) if (Array.isArray(s)) { add(s[0], s[1]); add(s[2], s[3]); }
  for (const r of w.robots) {
    if (w.kind !== 'plane') { add(r.lateral, 0); add(r.neutral, 0); }
    for (const l of r.links || []) if (isLink(l)) for (const [x, y] of linkEnds(l)) add(x, y);
  }
  if (!(b.x1 >= b.x0)) return world.box;
  const o = world.box;
  return o ? { x0: Math.min(o.x0, b.x0), x1: Math.max(o.x1, b.x1), y0: Math.min(o.y0, b.y0), y1: Math.max(o.y1, b.y1) } : b;
}

// The row's robots in their order along it (by neutral position: bodies on
// the line never pass each other), one lane each: bodies pressed together
// stand at the same x, and each is still seen.
const LANE = 16;
function rowLanes(w) {
  const idx = [];
  w.robots.forEach((r, i) => { if (fin(r.lateral)) idx.push(i); });
  const key = (i) => fin(w.robots[i].neutral) ? w.robots[i].neutral : w.robots[i].lateral;
  idx.sort((a, b) => key(a) - key(b) || a - b);
  const lane = new Map();
  idx.forEach((i, k) => lane.set(i, k));
  return { idx, lane };
}

// The canvas, sized for the box: world metres to CSS pixels (the plane: y up;
// the row: x only, a lane per robot below each other).
function worldView(canvas, box, plane, lanes) {
  const pad = 36, w = Math.max(box.x1 - box.x0, 0.05), h = plane ? Math.max(box.y1 - box.y0, 0.05) : 0;
  const cssH = plane ? Math.min(520, Math.max(160, (WORLD_W - 2 * pad) * h / w + 2 * pad))
                     : 2 * pad + Math.max(lanes - 1, 1) * LANE;
  const dpr = window.devicePixelRatio || 1;
  if (canvas.width !== Math.round(WORLD_W * dpr) || canvas.height !== Math.round(cssH * dpr)) {
    canvas.width = Math.round(WORLD_W * dpr); canvas.height = Math.round(cssH * dpr);
    canvas.style.width = WORLD_W + 'px'; canvas.style.height = cssH + 'px';
  }
  const s = plane ? Math.min((WORLD_W - 2 * pad) / w, (cssH - 2 * pad) / h) : (WORLD_W - 2 * pad) / w;
  const cx = (box.x0 + box.x1) / 2, cy = (box.y0 + box.y1) / 2;
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  return { ctx, s, dpr, cssH, px: (x) => WORLD_W / 2 + (x - cx) * s, py: (y) => cssH / 2 - (y - cy) * s,
           lane: (k) => pad + k * LANE };
}

function drawScale(v) {
  // a bar of a round length near 1/8 of the width
  const target = WORLD_W / 8 / v.s, pow = Math.pow(10, Math.floor(Math.log10(target)));
  const len = [1, 2, 5, 10].map(k => k * pow).filter(l => l <= target).pop() || pow;
  const { ctx } = v, x = 10, y = v.cssH - 10;
  ctx.strokeStyle = '#000'; ctx.lineWidth = 2; ctx.lineCap = 'butt';
  ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(x + len * v.s, y); ctx.stroke();
  ctx.fillStyle = '#000'; ctx.font = '11px sans-serif'; ctx.textAlign = 'left';
  ctx.fillText(len >= 1 ? `${len} m` : `${Math.round(len * 100 * 10) / 10} cm`, x + len * v.s + 4, y + 4);
}

function drawWalls(v, w) {
  const { ctx } = v;
  ctx.strokeStyle = '#555'; ctx.lineWidth = 4; ctx.lineCap = 'butt';
  for (const s of w.walls || []) {
    if (!Array.isArray(s) || !s.slice(0, 4).every(fin)) continue;
    ctx.beginPath(); ctx.moveTo(v.px(s[0]), v.py(s[1])); ctx.lineTo(v.px(s[2]), v.py(s[3])); ctx.stroke();
  }
  if (w.kind !== 'plane' && fin(w.wall_left) && fin(w.wall_right)) {
    ctx.lineWidth = 5;
    for (const x of [w.wall_left, w.wall_right]) {
      ctx.beginPath(); ctx.moveTo(v.px(x), 8); ctx.lineTo(v.px(x), v.cssH - 22); ctx.stroke();
    }
  }
}

// The plane's robots; returns what was drawn (link centres in device pixels, for tests)
function drawLinks(v, w) {
  const { ctx } = v, drawn = [];
  for (const r of w.robots) {
    const links = (r.links || []).filter(isLink);
    if (!links.length) continue;
    const color = robotColor(r.name), centres = [];
    ctx.strokeStyle = color; ctx.lineCap = 'round';
    for (const l of links) {
      const [a, b] = linkEnds(l);
      ctx.lineWidth = Math.max(4, l[4] * v.s);
      ctx.beginPath(); ctx.moveTo(v.px(a[0]), v.py(a[1])); ctx.lineTo(v.px(b[0]), v.py(b[1])); ctx.stroke();
      centres.push([Math.round(v.px(l[0]) * v.dpr), Math.round(v.py(l[1]) * v.dpr)]);
    }
    drawn.push({ name: r.name, color, centres, links: links.length });
  }
  // names after every link, beyond each head's front end; every other one
  // further out, so that neighbours side by side do not write over each other
  ctx.font = 'bold 11px sans-serif'; ctx.textAlign = 'center'; ctx.fillStyle = '#111';
  let k = 0;
  for (const r of w.robots) {
    const head = (r.links || [])[0];
    if (!isLink(head)) continue;
    const [, f] = linkEnds(head), ux = Math.cos(head[2]), uy = Math.sin(head[2]), d = k++ % 2 ? 23 : 11;
    ctx.fillText(r.name, v.px(f[0]) + ux * d, v.py(f[1]) - uy * d + 4);
  }
  return drawn;
}

function drawBodies(v, w, lanes) {
  const { ctx } = v, drawn = [];
  for (const i of lanes.idx) {
    const r = w.robots[i], y = v.lane(lanes.lane.get(i)), color = robotColor(r.name), x = v.px(r.lateral);
    ctx.strokeStyle = '#ccc'; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.moveTo(0, y); ctx.lineTo(WORLD_W, y); ctx.stroke();
    if (fin(r.neutral)) {
      ctx.strokeStyle = '#777';
      ctx.beginPath(); ctx.moveTo(v.px(r.neutral), y - 6); ctx.lineTo(v.px(r.neutral), y + 6); ctx.stroke();
    }
    ctx.fillStyle = color;
    ctx.beginPath(); ctx.arc(x, y, 6, 0, 2 * Math.PI); ctx.fill();
    ctx.fillStyle = '#111'; ctx.font = 'bold 11px sans-serif'; ctx.textAlign = 'left';
    ctx.fillText(r.name, x + 10, y + 4);
    drawn.push({ name: r.name, color, centres: [[Math.round(x * v.dpr), Math.round(y * v.dpr)]], links: 0 });
  }
  return drawn;
}

// the row: a mark between the lanes of its two robots (on its robot's lane
// for a wall); null when its robot has no lane
function rowMarkY(v, lanes, m) {
  const a = lanes.lane.get(m.a), b = m.b === -1 ? a : lanes.lane.get(m.b);
  return a === undefined || b === undefined ? null : (v.lane(a) + v.lane(b)) / 2;
}

function drawMarks(v, lanes) {
  const { ctx } = v;
  let n = 0;
  for (const m of world.marks) {
    const age = state.now - m.t;
    if (age < 0 || age > FADE_S) continue;
    const alpha = 1 - age / FADE_S, r = Math.min(22, 3 + 4 * Math.sqrt(m.f));
    const x = v.px(m.x), y = lanes ? rowMarkY(v, lanes, m) : v.py(m.y);
    if (y === null) continue;
    ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI);
    if (m.impact) { ctx.fillStyle = `rgba(214, 39, 40, ${alpha})`; ctx.fill(); }
    else { ctx.strokeStyle = `rgba(0, 0, 0, ${alpha})`; ctx.lineWidth = 2; ctx.stroke(); }
    n++;
  }
  return n;
}

function worldSummary(w) {
  const recent = world.marks.filter(m => state.now - m.t <= 1.0 && state.now >= m.t);
  const name = (i) => i === -1 ? 'a wall' : ((w.robots[i] || {}).name || '?');
  let top = null;
  for (const m of recent) if (!top || m.f > top.f) top = m;
  document.getElementById('world-summary').textContent = (world.simPresent ? '' : 'simulator not heard: the last world it sent · ') +
    `${recent.length} contact marks in the last second (${recent.filter(m => m.impact).length} impacts)` +
    (top ? ` · strongest: ${name(top.a)} – ${name(top.b)}, ${num(top.f, 2)} N` : '');
}

function drawWorld() {
  const w = world.last;
  if (!w) return;
  const trimTo = state.now - FADE_S;
  let k = 0;
  while (k < world.marks.length && world.marks[k].t < trimTo) k++;
  if (k) world.marks.splice(0, k);
  world.box = worldExtent(w);
  if (!world.box) return;
  const canvas = document.getElementById('worldcanvas'), plane = w.kind === 'plane';
  const lanes = plane ? null : rowLanes(w);
  const v = worldView(canvas, world.box, plane, lanes ? lanes.idx.length : 0);
  v.ctx.clearRect(0, 0, WORLD_W, v.cssH);
  v.ctx.fillStyle = world.simPresent ? '#fff' : '#eee';
  v.ctx.fillRect(0, 0, WORLD_W, v.cssH);
  drawWalls(v, w);
  world.drawn = plane ? drawLinks(v, w) : drawBodies(v, w, lanes);
  const marks = drawMarks(v, lanes);
  drawScale(v);
  // what was drawn, for whoever checks the page (tests/integration/web_cdp.py)
  Object.assign(canvas.dataset, { kind: w.kind, robots: world.drawn.length,
    links: world.drawn.reduce((n, d) => n + d.links, 0), marks });
  worldSummary(w);
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
    world.simPresent = st.sim.present;
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
  worldData(frame.world);
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
  drawWorld();
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

// The parameters, their ranges, units and steps: the server's table
// (common/params.h, served at /api/params), the one the daemon and
// undulate-top check against, never a copy of our own. A value outside its
// range is sent all the same: the server refuses it with the daemon's words.
const params = new Map();
function showRange() {
  const p = params.get(document.getElementById('p-name').value);
  const hint = document.getElementById('p-range');
  if (!p) { hint.textContent = ''; return; }
  const unit = p.unit ? ' ' + p.unit : '';
  hint.textContent = `range ${p.range}${unit}, step ${p.step}` + (p.per_joint ? '' : ' (per robot: joint -1)');
  document.getElementById('p-value').title = `${p.name}: ${p.range}${unit}`;
}
async function loadParams() {
  const select = document.getElementById('p-name');
  try {
    const r = await fetch('/api/params', { cache: 'no-store' });
    for (const p of await r.json()) {
      params.set(p.name, p);
      const o = document.createElement('option');
      o.value = o.textContent = p.name;
      select.appendChild(o);
    }
    select.value = params.has('c') ? 'c' : select.value;
  } catch (e) {
    document.getElementById('p-range').textContent = 'parameter list not loaded: ' + e;
  }
  showRange();
}
document.getElementById('p-name').addEventListener('change', showRange);
loadParams();

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
