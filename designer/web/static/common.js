// What every page shares: the API call, the form's options, the one-line refusal shown beside its field,
// the plots (uPlot, served from this server), tables and downloads. No build step: plain ES2017.
"use strict";

const D = {};

D.choices = null;
D.loadChoices = async function () {
  if (!D.choices) D.choices = await (await fetch("/api/choices")).json();
  return D.choices;
};

// POST a JSON body (or a FormData, or a File as the body); resolves {ok, status, data, blob}. A call with a
// ``channel`` aborts the one before it on that channel (the form typed on: the server drops it if queued),
// and resolves {aborted: true} when it is itself aborted.
// Every call says it is this page's (X-Designer): the server takes an upload's form or file only with it, which
// a page of another site cannot send without asking the server first (a CORS preflight it never approves).
const channels = {};
D.api = async function (path, body, asBlob, channel) {
  const init = {method: "POST", headers: {"X-Designer": "1"}};
  if (body instanceof FormData || body instanceof Blob) init.body = body;
  else { init.body = JSON.stringify(body || {}); init.headers["Content-Type"] = "application/json"; }
  if (channel) {
    if (channels[channel]) channels[channel].abort();
    channels[channel] = new AbortController();
    init.signal = channels[channel].signal;
  }
  let r;
  try { r = await fetch(path, init); } catch (e) {
    if (e.name === "AbortError") return {aborted: true};
    return {ok: false, status: 0, data: {error: `the server does not answer: ${e.message}`, message: "the server does not answer"}};
  }
  if (r.ok && asBlob) {
    const named = /filename="([^"]+)"/.exec(r.headers.get("Content-Disposition") || "");
    return {ok: true, status: r.status, blob: await r.blob(), filename: named ? named[1] : null};
  }
  let data = null;
  try { data = await r.json(); } catch (e) { data = {error: `HTTP ${r.status}`, message: `HTTP ${r.status}`}; }
  return {ok: r.ok, status: r.status, data};
};

// A form answers as it is typed: Enter never submits it (the pages' Content-Security-Policy has no inline script,
// so this is not an onsubmit attribute).
document.addEventListener("submit", e => e.preventDefault());

D.debounce = function (fn, ms) {
  let timer = null;
  return function (...args) { clearTimeout(timer); timer = setTimeout(() => fn(...args), ms); };
};

// The form's options by name: empty fields left out (the command's defaults), checkboxes as switches.
D.options = function (form) {
  const out = {};
  for (const el of form.querySelectorAll("[name]")) {
    if (el.disabled || el.closest("[hidden]")) continue;
    if (el.type === "checkbox") { if (el.checked) out[el.name] = true; continue; }
    if (el.type === "radio") { if (el.checked) out[el.name] = el.value; continue; }
    const v = el.value.trim();
    if (v !== "") out[el.name] = v;
  }
  return out;
};

// The command's one line beside the field it names (the form's foot when it names none): one message.
D.clearError = function (form) {
  for (const el of form.querySelectorAll(".field-error")) el.remove();
  for (const el of form.querySelectorAll(".bad")) el.classList.remove("bad");
};
D.showError = function (form, data) {
  D.clearError(form);
  const msg = document.createElement("div");
  msg.className = "field-error";
  msg.setAttribute("role", "alert");
  msg.textContent = data.message || data.error;
  msg.title = data.error || "";
  const name = data.option ? data.option.replace(/^--/, "") : null;
  const field = name ? form.querySelector(`[name="${CSS.escape(name)}"]`) : null;
  if (field && !field.closest("[hidden]")) {
    field.classList.add("bad");
    (field.closest("label") || field).after(msg);
  } else {
    form.querySelector(".form-foot").append(msg);
  }
};

// Each answer shown: the page's state ("done" or "error") and how many answers it has shown (for its tests).
D.answered = function (state) {
  document.body.dataset.state = state;
  // after a refusal the results shown are the last good input's: dimmed until the form is right again
  for (const r of document.querySelectorAll(".results")) r.classList.toggle("stale", state === "error");
  document.body.dataset.answers = String(+(document.body.dataset.answers || 0) + 1);
};

D.busy = function (on, el) {
  document.body.classList.toggle("busy", on);
  if (el) el.textContent = on ? "working..." : "";
};

// Engineering notation with the unit: 1.6 kOhm, 3.3 nF, 97.9 us.
D.eng = function (v, unit, digits) {
  if (v === null || v === undefined || !isFinite(v)) return "n/a";
  digits = digits || 4;
  if (v === 0) return `0 ${unit || ""}`.trim();
  const pre = [[1e12, "T"], [1e9, "G"], [1e6, "M"], [1e3, "k"], [1, ""], [1e-3, "m"], [1e-6, "u"], [1e-9, "n"],
               [1e-12, "p"], [1e-15, "f"]];
  const a = Math.abs(v);
  for (const [f, p] of pre) if (a >= f * 0.9995) return `${+(v / f).toPrecision(digits)} ${p}${unit || ""}`.trim();
  return `${v.toPrecision(digits)} ${unit || ""}`.trim();
};

D.table = function (header, rows, cls) {
  const t = document.createElement("table");
  if (cls) t.className = cls;
  const h = t.createTHead().insertRow();
  for (const c of header) { const th = document.createElement("th"); th.textContent = c; h.append(th); }
  const b = t.createTBody();
  for (const r of rows) {
    const tr = b.insertRow();
    for (const c of r) {
      const td = tr.insertCell();
      if (c instanceof Node) td.append(c); else td.textContent = c === null || c === undefined ? "" : String(c);
    }
  }
  return t;
};

// one figure of a result: its value large, its label below
D.fig = function (label, value) {
  const d = document.createElement("div");
  d.className = "figure";
  d.innerHTML = "<b></b><span></span>";
  d.querySelector("b").textContent = value;
  d.querySelector("span").textContent = label;
  return d;
};

D.checksTable = function (checks) {
  return D.table(["check", "result", "detail"], checks.map(c => {
    const s = document.createElement("span");
    s.className = c.ok ? "ok" : "fail";
    s.textContent = c.ok ? "ok" : "FAILED";
    return [c.title || c.id, s, c.detail];
  }));
};

D.download = function (blob, name) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.append(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
};

const COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"];

// One interactive plot (uPlot): drag to zoom, double-click to reset, click a legend entry to hide its trace.
D.plot = function (el, trace, opts) {
  opts = opts || {};
  if (el._plot) { el._plot.destroy(); el._plot = null; }
  el.innerHTML = "";
  const data = [trace.x, ...trace.series.map(s => s.y)];
  const width = Math.max(320, el.clientWidth || 640);
  const series = [{label: trace.x_label}];
  trace.series.forEach((s, i) => {
    const band = /^tolerance band/.test(s.label);
    const points = /^(data|SPICE \.ac)$/.test(s.label);
    series.push({label: s.label, stroke: band ? "#e0a040" : COLOURS[i % COLOURS.length],
                 width: i === 0 && !band ? 2.5 : 1.5, dash: band ? [4, 4] : undefined,
                 spanGaps: false, points: points ? {show: true, size: 5} : {show: false},
                 paths: points ? () => null : undefined});
  });
  const u = new uPlot({
    title: opts.title || "", width, height: opts.height || 300, series,
    scales: {x: trace.log_x ? {time: false, distr: 3} : {time: false}},
    // a log axis labels its decades only (uPlot gives null for the ticks it leaves bare)
    axes: [{label: trace.x_label, values: (u, ticks) => ticks.map(t => t === null || (trace.log_x &&
              Math.abs(Math.log10(t) - Math.round(Math.log10(t))) > 1e-9) ? "" : D.eng(t, opts.xUnit || "", 3))},
           {label: opts.yLabel || ""}],
    cursor: {drag: {x: true, y: false}},
    legend: {live: true},
  }, data, el);
  el._plot = u;
  el.dataset.series = trace.series.map(s => s.label).join("|");
  return u;
};

D.nav = function (current) {
  const nav = document.querySelector("nav");
  for (const [href, text] of [["/plant", "Plant"], ["/pid", "PID"], ["/identify", "Identify"], ["/check", "Check"]]) {
    const a = document.createElement("a");
    a.href = href; a.textContent = text;
    if (href === current) a.className = "here";
    nav.append(a);
  }
};

// Fill a <select> with names (keeping the value chosen, else the default).
D.fill = function (select, names, def) {
  const keep = select.value;
  select.innerHTML = "";
  for (const n of names) { const o = document.createElement("option"); o.value = o.textContent = n; select.append(o); }
  select.value = keep && names.includes(keep) ? keep : def;
};

// A dropped or chosen file, wired to a callback.
D.dropZone = function (zone, input, onFile) {
  zone.addEventListener("dragover", e => { e.preventDefault(); zone.classList.add("over"); });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", e => {
    e.preventDefault(); zone.classList.remove("over");
    if (e.dataTransfer.files.length) onFile(e.dataTransfer.files);
  });
  input.addEventListener("change", () => { if (input.files.length) onFile(input.files); });
};
