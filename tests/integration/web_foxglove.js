// web_foxglove.js — a Foxglove client of undulate-web for web_foxglove.sh,
// written with the published client library (@foxglove/ws-protocol, found
// through NODE_PATH) over node's own WebSocket (--experimental-websocket).
// Prints one JSON object (what it saw) on stdout; the shell asserts on it.
//
//   node web_foxglove.js watch URL TOPIC SECONDS   serverInfo, channels, subscribe to TOPIC,
//                                                   count messages, unsubscribe, count again
//   node web_foxglove.js hostile URL TOPIC         bad JSON, unknown ops, huge and binary
//                                                   frames, unknown and too many subscriptions
//   node web_foxglove.js quiet URL TOPIC SECONDS   subscribe, then wait for TOPIC's unadvertise
//   node web_foxglove.js crowd URL N               open N connections: how many were taken
"use strict";
const { FoxgloveClient } = require("@foxglove/ws-protocol");

const [mode, url, arg, arg2] = process.argv.slice(2);
const SUB = FoxgloveClient.SUPPORTED_SUBPROTOCOL;
const out = {};
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const done = (code) => { console.log(JSON.stringify(out)); process.exit(code); };
setTimeout(() => { out.timeout = true; done(1); }, 60000).unref();

// Resolves when pred() holds, rejects after ms.
async function until(pred, ms, what) {
	const end = Date.now() + ms;
	while (!pred()) {
		if (Date.now() > end) throw new Error("timed out waiting for " + what);
		await sleep(20);
	}
}

function connect() {
	const ws = new WebSocket(url, [SUB]);
	const c = new FoxgloveClient({ ws });
	const s = { ws, c, info: null, channels: new Map(), removed: [], status: [], msgs: [], errors: [], closed: null };
	c.on("serverInfo", (i) => { s.info = i; });
	c.on("advertise", (chs) => chs.forEach((ch) => s.channels.set(ch.id, ch)));
	c.on("unadvertise", (ids) => ids.forEach((id) => { s.removed.push(id); s.channels.delete(id); }));
	c.on("status", (m) => s.status.push(m));
	c.on("message", (m) => s.msgs.push(m));
	c.on("error", (e) => s.errors.push(String(e && e.message ? e.message : e)));
	c.on("close", (e) => { s.closed = { code: e.code, reason: e.reason }; });
	return s;
}

function topicChannel(s, topic) {
	for (const ch of s.channels.values()) if (ch.topic === topic) return ch;
	return null;
}

async function watch() {
	const seconds = Number(arg2 || 3);
	const s = connect();
	await until(() => s.info !== null, 10000, "serverInfo");
	out.serverInfo = s.info;
	await until(() => topicChannel(s, arg) !== null, 10000, "the channel " + arg);
	await sleep(1500); // the other kinds of message: BUS once a second, PARAMS, EVENT
	out.channels = [...s.channels.values()].map((ch) => {
		let schema = null;
		try { schema = JSON.parse(ch.schema); } catch (e) { schema = { unparsable: String(e) }; }
		return { id: ch.id, topic: ch.topic, encoding: ch.encoding, schemaName: ch.schemaName,
		         schemaEncoding: ch.schemaEncoding, schema };
	});
	const ch = topicChannel(s, arg);
	const sub = s.c.subscribe(ch.id);
	await until(() => s.msgs.length > 0, 5000, "a first message");
	const first = s.msgs.length;
	const t0 = Date.now();
	await sleep(seconds * 1000);
	const n = s.msgs.length - first, dt = (Date.now() - t0) / 1000;
	const dec = new TextDecoder();
	const parsed = s.msgs.slice(first).map((m) => JSON.parse(dec.decode(m.data)));
	const now_ns = BigInt(Date.now()) * 1000000n;
	out.sub = sub;
	out.count = n;
	out.seconds = dt;
	out.rate = n / dt;
	out.subIds = [...new Set(s.msgs.map((m) => m.subscriptionId))];
	out.cycles = parsed.length ? parsed[parsed.length - 1].cycle - parsed[0].cycle + 1 : 0;
	out.sample = parsed[parsed.length - 1];
	out.stampAgeMs = s.msgs.length ? Number(now_ns - s.msgs[s.msgs.length - 1].timestamp) / 1e6 : null;
	s.c.unsubscribe(sub);
	await sleep(500); // what was on its way
	const after = s.msgs.length;
	await sleep(1000);
	out.afterUnsubscribe = s.msgs.length - after;
	out.status = s.status;
	out.errors = s.errors;
	s.c.close();
	done(0);
}

// Sends raw text (or bytes) on the socket and waits for the next status
// (the next one whose message matches re, when statuses of earlier messages
// may still be on their way).
async function expectStatus(s, payload, what, re) {
	const before = s.status.length;
	const match = () => s.status.slice(before).find((m) => !re || re.test(m.message));
	s.ws.send(payload);
	try {
		await until(() => match() || s.closed, 10000, "a status for " + what);
	} catch (e) {
		return { what, status: null };
	}
	const m = match();
	return { what, level: m ? m.level : null, message: m ? m.message : null, closed: s.closed };
}

async function hostile() {
	const s = connect();
	await until(() => s.info !== null && topicChannel(s, arg) !== null, 10000, "serverInfo and " + arg);
	const ch = topicChannel(s, arg);
	const r = [];
	r.push(await expectStatus(s, "this is not JSON {", "bad JSON"));
	r.push(await expectStatus(s, JSON.stringify({ op: "launchMissiles" }), "unknown op"));
	r.push(await expectStatus(s, JSON.stringify({ op: "advertise", channels: [{ id: 1, topic: "x.CMD",
		encoding: "json", schemaName: "x" }] }), "client advertise (no clientPublish)"));
	r.push(await expectStatus(s, new Uint8Array([1, 1, 0, 0, 0, 123]), "binary client message data"));
	r.push(await expectStatus(s, JSON.stringify({ op: "subscribe", subscriptions: [{ id: 7, channelId: 999999 }] }),
		"subscribe to an unknown channel"));
	r.push(await expectStatus(s, JSON.stringify({ op: "unsubscribe", subscriptionIds: [424242] }),
		"unsubscribe an unknown subscription"));
	r.push(await expectStatus(s, JSON.stringify({ op: "subscribe", subscriptions: [{ id: "x", channelId: ch.id }] }),
		"a subscription id that is not a number"));
	r.push(await expectStatus(s, JSON.stringify({ op: "subscribe", padding: "a".repeat(1 << 20),
		subscriptions: [{ id: 1, channelId: ch.id }] }), "a 1 MB message", /longer than/));
	// thousands of subscriptions, one message each: a few are taken, the rest refused
	const before = s.status.length;
	for (let i = 0; i < 3000; i++)
		s.ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1000 + i, channelId: ch.id }] }));
	await until(() => s.status.length > before || s.closed, 10000, "a status for 3000 subscriptions").catch(() => {});
	const m = s.status[before];
	r.push({ what: "3000 subscriptions", level: m ? m.level : null, message: m ? m.message : null });
	// the same again in one message
	const many = [];
	for (let i = 0; i < 3000; i++) many.push({ id: 10000 + i, channelId: ch.id });
	r.push(await expectStatus(s, JSON.stringify({ op: "subscribe", subscriptions: many }),
		"3000 subscriptions in one message", /longer than/));
	out.cases = r;
	await sleep(1000);
	const subs = new Set(s.msgs.map((x) => x.subscriptionId));
	out.subscriptionsServed = subs.size;
	out.stillOpen = s.closed === null;
	out.messagesAfter = s.msgs.length;
	out.closed = s.closed;
	out.errors = s.errors;
	s.c.close();
	done(0);
}

// Subscribes to TOPIC, says so on stderr, then waits (up to SECONDS) for
// the channel to be unadvertised once its source stops.
async function quiet() {
	const s = connect();
	await until(() => s.info !== null && topicChannel(s, arg) !== null, 10000, "serverInfo and " + arg);
	const ch = topicChannel(s, arg);
	s.c.subscribe(ch.id);
	await until(() => s.msgs.length > 0, 5000, "a first message");
	console.error("subscribed to " + arg);
	const t0 = Date.now();
	await until(() => s.removed.includes(ch.id), Number(arg2 || 30) * 1000, "the unadvertise of " + arg).catch(() => {});
	out.unadvertised = s.removed.includes(ch.id);
	out.afterSeconds = (Date.now() - t0) / 1000;
	const n = s.msgs.length;
	await sleep(500);
	out.messagesAfter = s.msgs.length - n;
	out.othersLive = [...s.channels.values()].map((c) => c.topic);
	s.c.close();
	done(0);
}

async function crowd() {
	const n = Number(arg);
	const socks = [];
	for (let i = 0; i < n; i++) socks.push(connect());
	await until(() => socks.every((s) => s.info !== null || s.closed !== null || s.errors.length), 15000,
		"every connection to open or fail").catch(() => {});
	out.taken = socks.filter((s) => s.info !== null && s.closed === null).length;
	out.refused = n - out.taken;
	socks.forEach((s) => s.c.close());
	done(0);
}

const modes = { watch, hostile, quiet, crowd };
if (!modes[mode]) {
	console.error("usage: web_foxglove.js watch|hostile|crowd URL ARG");
	process.exit(2);
}
modes[mode]().catch((e) => { out.error = String(e && e.stack ? e.stack : e); done(1); });
