// What every page shares: the API call, the form's options, the one-line refusal shown beside its field,
// the plots (uPlot, served from this server), tables and downloads. No build step: plain ES2017.
"use strict";

const D = {};

// The page's words in the reader's language: every string the page shows goes through D.t (the English text is
// the key; {name} placeholders filled from params). English is the identity until a catalogue is loaded.
D.catalogue = {};
// a word marked for the catalogue where it is written, translated (D.t) where it is shown
D.N_ = text => text;
D.t = function (text, params) {
  let s = D.catalogue[text] || text;
  if (params) for (const k of Object.keys(params)) s = s.split("{" + k + "}").join(String(params[k]));
  return s;
};

// The page's language: the address's ?lang= (the menu's choice, kept in every link the page makes), else the
// browser's preference (navigator.languages: what it sends as Accept-Language), else English. The catalogue
// (GET /api/catalogue: the same Babel catalogue as the build sheets) is loaded before a page draws anything.
D.LANGUAGES = {en: "English", es: "Español"};
D.lang = (function () {
  const asked = new URLSearchParams(location.search).get("lang");
  if (asked && D.LANGUAGES[asked]) return asked;
  for (const tag of navigator.languages || [navigator.language || ""]) {
    const code = String(tag).toLowerCase().split("-")[0];
    if (D.LANGUAGES[code]) return code;
  }
  return "en";
})();
D.decimal = ".";
D.ready = (async function () {
  document.documentElement.lang = D.lang;
  if (D.lang === "en") return;
  try {
    const c = await (await fetch(`/api/catalogue?lang=${encodeURIComponent(D.lang)}`)).json();
    D.catalogue = c.messages || {};
    D.decimal = c.decimal || ".";
  } catch (e) { /* no catalogue: the page stays in English */ }
  const go = () => D.translatePage(document.body);
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", go); else go();
  document.title = D.t(document.title);
})();
// The page's HTML in the page's language: each text between tags (spaces collapsed: the catalogue's key) and
// the attributes a reader sees or hears; an element marked translate="no" (names, a file's example) is left.
D.ATTRIBUTES = ["placeholder", "title", "aria-label", "alt"];
D.translatePage = function (root) {
  const walk = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  for (let n = walk.nextNode(); n; n = walk.nextNode()) {
    if (n.parentElement && n.parentElement.closest("script, style, [translate=no]")) continue;
    const key = n.textContent.replace(/\s+/g, " ").trim();
    if (key && D.catalogue[key]) {
      const lead = /^\s*/.exec(n.textContent)[0], tail = /\s*$/.exec(n.textContent)[0];
      n.textContent = lead + D.catalogue[key] + tail;
    }
  }
  for (const el of root.querySelectorAll(D.ATTRIBUTES.map(a => `[${a}]`).join(","))) {
    if (el.closest("[translate=no]")) continue;
    for (const a of D.ATTRIBUTES) {
      const v = el.getAttribute(a);
      if (v && D.catalogue[v.replace(/\s+/g, " ").trim()]) el.setAttribute(a, D.catalogue[v.replace(/\s+/g, " ").trim()]);
    }
  }
};
// A number as the page's language writes it: a decimal comma in Spanish, and there the SI signs (µ, Ω) as the
// Spanish sheets write them (designer.core.i18n.localise does the same on the server).
D.localNum = function (text) {
  if (D.lang === "en") return text;
  return String(text).replace(/(^|[^A-Za-z_.\d])(\d+)\.(\d+)(?!\.?\d)/g, (all, pre, a, b) => `${pre}${a}${D.decimal}${b}`)
    .replace(/(\d )([fpnumkMG]?)Ohm\b/g, "$1$2Ω").replace(/(\d )u(?=(?:s|F|V|A|H|Hz)\b)/g, "$1µ");
};
// A number typed as the page's language writes it ("0,5" in Spanish) as the API reads it ("0.5"): both are taken.
D.typed = function (v) {
  return D.lang === "en" ? v : v.replace(/(\d),(\d)/g, "$1.$2");
};

D.choices = null;
D.loadChoices = async function () {
  await D.ready;
  if (!D.choices) D.choices = await (await fetch("/api/choices")).json();
  return D.choices;
};

// POST a JSON body (or a FormData, or a File as the body); resolves {ok, status, data, blob}. A call with a
// ``channel`` aborts the one before it on that channel (the form typed on: the server drops it if queued),
// and resolves {aborted: true} when it is itself aborted.
// Every call says it is this page's (X-Designer): the server takes an upload's form or file only with it, which
// a page of another site cannot send without asking the server first (a CORS preflight it never approves).
const channels = {};
// Abort the request in flight on a channel: the browser closes its connection, which the server sees (a queued
// request leaves the queue, its worker never starts it).
D.cancel = function (channel) {
  if (channels[channel]) { channels[channel].abort(); delete channels[channel]; }
};
// the commands answer in the page's language (their --lang): the design and analysis commands take it among
// their fields, check-design among its options (the JSON's "options"); identify in its query (identify.js)
D.SPEAKS = /^\/api\/(analyze-)?(plant|pid|filter)(\/|\?|$)/;
D.SPEAKS_IN_OPTIONS = /^\/api\/check(\?|$)/;
D.api = async function (path, body, asBlob, channel) {
  if (D.lang !== "en" && body && body.constructor === Object) {
    if (D.SPEAKS.test(path)) body = {...body, lang: D.lang};
    else if (D.SPEAKS_IN_OPTIONS.test(path)) body = {...body, options: {...(body.options || {}), lang: D.lang}};
  }
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
    if (channel) delete channels[channel];
    return {ok: false, status: 0, data: {error: `the server does not answer: ${e.message}`,
                                         message: D.t("the server does not answer")}};
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

// The form's options by name: empty fields left out (the command's defaults), checkboxes as switches.
D.options = function (form) {
  const out = {};
  for (const el of form.querySelectorAll("[name]")) {
    if (el.disabled || el.closest("[hidden]")) continue;
    if (el.type === "checkbox") { if (el.checked) out[el.name] = true; continue; }
    if (el.type === "radio") { if (el.checked) out[el.name] = el.value; continue; }
    const v = el.tagName === "INPUT" ? D.typed(el.value.trim()) : el.value.trim();
    if (v !== "") out[el.name] = v;
  }
  return out;
};

// The command's one line beside the field it names (the form's foot when it names none): one message.
D.clearError = function (form) {
  for (const el of form.querySelectorAll(".field-error")) el.remove();
  for (const el of form.querySelectorAll(".bad")) el.classList.remove("bad");
};
// A field's label as the page shows it ("zeta", "target overshoot (%)"): its <label>'s own text, not the hint.
D.labelOf = function (form, name) {
  const field = form.querySelector(`[name="${CSS.escape(name)}"]`);
  const label = field && field.closest("label");
  if (!label) return null;
  let text = "";
  for (const n of label.childNodes) if (n.nodeType === Node.TEXT_NODE) text += n.textContent;
  return text.replace(/\s+/g, " ").trim() || null;
};

// A command's message in the page's words: each "--flag" (with its metavariable, "--target-overshoot P (percent)")
// becomes the label of the field that sets it (the API names the flag in its `option`; the form's labels name
// the fields), one with no field on this page its plain name; references to the seed documents are left out
// (they mean nothing beside a form).
D.inPageWords = function (form, text, keepRefs) {
  const label = name => (form && D.labelOf(form, name)) || D.t(name.replace(/-/g, " "));
  // the optimiser's two sentences say what to do: in the page, with its menu and field
  text = String(text || "")
    .replace(/--tuning (\S+) needs --target-overshoot P \(percent\)/g,
             (all, rule) => D.t('the rule "{rule}" needs a target: fill in "{field}"', {rule, field: label("target-overshoot")}))
    // ... as the library-first API words it, its fields by their labels already
    .replace(/^"[^"]+" (\S+) needs "([^"]+)" P \(percent\)/,
             (all, rule, field) => D.t('the rule "{rule}" needs a target: fill in "{field}"', {rule, field}))
    .replace(/--tuning (\S+) --target-overshoot P\b/g,
             (all, rule) => D.t('choose the rule "{rule}" and fill in "{field}"', {rule, field: label("target-overshoot")}));
  text = text.replace(/--([a-z][a-z0-9-]*)(?: [A-Z][A-Z_]*\b)?(?: \((?:percent|s|Hz|V)\))?/g, (all, name) => {
    return `"${label(name)}"`;
  });
  return keepRefs ? text : D.plainText(text);
};
D.plainText = function (text) {
  return String(text || "").replace(/,?\s*seed \d{3}[^,;:)]*/gi, "").replace(/\s*\(\s*\)/g, "").replace(/\(\s*,\s*/g, "(");
};

D.showError = function (form, data) {
  D.clearError(form);
  const msg = document.createElement("div");
  msg.className = "field-error";
  msg.setAttribute("role", "alert");
  msg.textContent = D.inPageWords(form, data.message || data.error);
  msg.title = data.error || "";    // the command's own line, for whoever reports it
  const name = data.option ? data.option.replace(/^--/, "") : null;
  const field = name ? form.querySelector(`[name="${CSS.escape(name)}"]`) : null;
  if (field && !field.closest("[hidden]")) {
    field.classList.add("bad");
    (field.closest("label") || field).after(msg);
  } else {
    form.querySelector(".form-foot").append(msg);
  }
};

// What the results show is of the inputs as they were: while a newer request is on its way, or after the
// current inputs were refused, every result control (data-current: downloads, "a PID for this plant"...) is
// off and one note above the results says why. A page clears what must not be read at all (a check table)
// in its own onStale.
D.STALE = {
  refused: D.N_("The inputs are refused (see the form): what is shown below is the last design that worked, not of " +
                "the current inputs. Its downloads are off until the form is right again."),
  pending: D.N_("Working on the new inputs: what is shown below is of the previous ones."),
};
D.onStale = null;
D.markStale = function (why) {
  for (const el of document.querySelectorAll("[data-current]")) el.disabled = true;
  const results = document.querySelector(".results");
  // before the first answer there is nothing shown to warn about
  if (!results || (why === "pending" && !+(document.body.dataset.answers || 0))) return;
  let note = document.getElementById("stale-note");
  if (!note) {
    note = document.createElement("p");
    note.id = "stale-note";
    note.className = "stale-note";
    note.setAttribute("role", "status");
    results.prepend(note);
  }
  note.textContent = D.t(D.STALE[why] || why);
  note.dataset.why = why;
  note.hidden = false;
  results.classList.add("stale");
  if (D.onStale) D.onStale(why);
};
// whether what is shown is not of the current inputs (a result control's handler does nothing then: a
// script's click reaches it even when it is disabled)
D.isStale = function () {
  return document.querySelector(".results.stale") !== null;
};
D.markCurrent = function () {
  for (const el of document.querySelectorAll("[data-current]")) el.disabled = false;
  const note = document.getElementById("stale-note");
  if (note) note.hidden = true;
  for (const r of document.querySelectorAll(".results")) r.classList.remove("stale");
};

// A form answering as it is typed: a keystroke cancels the request in flight (browser and server: its answer
// would be of the inputs before it) and waits for a pause (`wait` ms: no refusal of the "0." on the way to
// "0.05", no design per key); leaving a field or choosing from a menu asks at once. `key()` is what the request
// would send: the inputs last asked for are not asked again when nothing was typed since (leaving the field
// whose pause already sent them). Typing back to the inputs whose answer is drawn (a digit typed and erased, a value
// retyped as it was) asks nothing: that answer is current again, and a request sent meanwhile is cancelled.
D.UNFINISHED = /(^\s*[-+]?\s*$)|(\d[.,]|\d[eE][-+]?|[-+])\s*$/;
// The pause: 250 ms, or 1.3 times the typist's own gap between keys when that is longer (up to 700 ms), so a
// slow typist is not answered at every key; 600 ms while that gap is not known yet (the page's first key).
// A superseded request is stopped on the server too (its worker freed at once), so asking early costs the
// room little (issue 29: last key to drawn under 0.5 s).
D.DEBOUNCE_MS = 250;
D.DEBOUNCE_MAX_MS = 700;
D.DEBOUNCE_FIRST_MS = 600;
D.liveForm = function (form, run, key, wait) {
  let timer = null, asked = null, lastKey = 0, gap = 0;
  // the inputs whose answer is drawn: their key, the page's answer count then, its status line
  let shown = null;
  const answersNow = () => +(document.body.dataset.answers || 0);
  const pause = () => wait || (gap ? Math.min(D.DEBOUNCE_MAX_MS, Math.max(D.DEBOUNCE_MS, 1.3 * gap))
                                     : D.DEBOUNCE_FIRST_MS);
  const now = () => {
    clearTimeout(timer); timer = null;
    const k = key();
    if (k !== null && k === asked) return;   // nothing typed since: its answer is shown or on its way
    asked = k;
    const n = answersNow();
    Promise.resolve(run()).then(() => {
      // drawn for these inputs: answered since, nothing asked since, and not a refusal
      if (k !== null && asked === k && answersNow() > n && document.body.dataset.state === "done") {
        const status = document.getElementById("status");
        // (and which of its controls the page left off: "a PID for this model" without a valid model)
        const off = [...document.querySelectorAll("[data-current]")].filter(el => el.disabled);
        shown = {k, n: answersNow(), said: status ? status.textContent : "", off};
      }
    });
  };
  // the inputs are back to those of the answer drawn, nothing answered since: current again, nothing asked
  const restored = () => {
    const k = key();
    if (!shown || k === null || k !== shown.k || answersNow() !== shown.n) return false;
    D.cancel("form");
    asked = k;
    const status = document.getElementById("status");
    D.busy(false, status);
    if (status) status.textContent = shown.said;
    D.markCurrent();
    for (const el of shown.off) el.disabled = true;
    return true;
  };
  form.addEventListener("input", e => {
    if (e.target.type === "file") return;
    const t = performance.now();
    // a gap between two keys of a burst of typing (a new burst keeps the last; a field emptied, a paste or a
    // script's fill, two events within 30 ms, say nothing of the typist)
    if (e.target.value !== "") {
      if (t - lastKey < 1500 && t - lastKey > 30) gap = t - lastKey;
      lastKey = t;
    }
    clearTimeout(timer);
    if (restored()) return;
    D.cancel("form");
    asked = null;
    D.markStale("pending");
    // a number still being typed ("0.", "1e", "-") is not asked about on a pause, only when the field is left
    if (!(e.target.tagName === "INPUT" && D.UNFINISHED.test(e.target.value))) timer = setTimeout(now, pause());
  });
  form.addEventListener("change", e => { if (e.target.type !== "file") now(); });
  // back and forward move between the designs shown: the fields as that address has them, asked at once
  window.addEventListener("popstate", () => {
    D.fillFromQuery(form);
    if (D.onRestore) D.onRestore();
    D.history.restoring = true;
    clearTimeout(timer);
    D.cancel("form");
    asked = null;
    now();
  });
  return {now, forget: () => { asked = null; }};
};

// A design page's two actions (Plant, Filter): `design()` posts the form to `endpoint?view=page` (a newer one
// supersedes it), shows the answer with `show` and `said(answer)` on the status line, or the refusal beside its
// field; `file(kind)` downloads "bom" (from the answer), "sheet" (opened in a tab to print) or "bundle" of the
// design shown, never of inputs it is not of. `shown()` is that design: {opts, answer}, or null.
D.designPage = function (form, status, endpoint, show, said) {
  let seq = 0, last = null;
  async function design() {
    const mine = ++seq;
    const opts = D.options(form);
    D.markStale("pending");
    D.busy(true, status);
    const r = await D.api(`${endpoint}?view=page`, opts, false, "form");
    if (r.aborted || mine !== seq) return;          // a newer request is on its way: this answer is stale
    D.busy(false, status);
    if (!r.ok) { D.showError(form, r.data); D.answered("error"); return; }
    D.clearError(form);
    last = {opts, answer: r.data};   // the downloads are of these inputs (D.answered turns them on)
    D.remember(opts);
    show(r.data);
    status.textContent = said(r.data);
    D.answered("done");
  }
  async function file(kind) {
    if (!last || D.isStale()) return;
    if (kind === "bom") {
      D.download(new Blob([last.answer.page.bom_csv], {type: "text/csv"}), "bom.csv");
      return;
    }
    D.busy(true, status);
    const r = await D.api(`${endpoint}/${kind}`, last.opts, true);
    D.busy(false, status);
    if (!r.ok) { D.showError(form, r.data); return; }
    // the sheet in a new tab to print; a browser that blocks the tab gets it as a file
    if (kind === "sheet") { if (!window.open(URL.createObjectURL(r.blob), "_blank")) D.download(r.blob, "build-sheet.html"); }
    else D.download(r.blob, r.filename || "design.zip");   // the design's name, as its command names it
  }
  return {design, file, shown: () => last};
};

// Each answer shown: the page's state ("done" or "error") and how many answers it has shown (for its tests).
D.answered = function (state) {
  document.body.dataset.state = state;
  // after a refusal the results shown are the last good input's: off until the form is right again
  if (state === "error") {
    D.markStale("refused");
    document.body.dataset.refusals = String(+(document.body.dataset.refusals || 0) + 1);
  } else D.markCurrent();
  document.body.dataset.answers = String(+(document.body.dataset.answers || 0) + 1);
};

// The inputs of the design shown, in the address bar: a link to share, a reload that keeps them (the pages
// read their fields from the query string as they open, D.fillFromQuery). Each new design is a history entry
// (back and forward move between them, D.liveForm); the page's first, and one restored by back or forward,
// replace theirs.
D.history = {first: true, restoring: false};
D.remember = function (opts) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(opts)) {
    if (Array.isArray(v)) q.set(k, v.join(" "));   // a field's items apart, as typed
    else if (typeof v !== "object") q.set(k, v === true ? "true" : v);
  }
  // the language chosen goes with the link (English too when chosen: the reader's browser may prefer another)
  if (D.lang !== "en" || new URLSearchParams(location.search).has("lang")) q.set("lang", D.lang);
  const url = `${location.pathname}?${q}`;
  if (url !== location.pathname + location.search) {
    if (D.history.first || D.history.restoring) history.replaceState({designer: true}, "", url);
    else history.pushState({designer: true}, "", url);
  }
  D.history.first = false;
  D.history.restoring = false;
};
// The form's fields as the address has them; a field it does not name back to its default.
D.fillFromQuery = function (form) {
  const q = new URLSearchParams(location.search);
  for (const el of form.querySelectorAll("[name]")) {
    if (el.type === "file") continue;
    const v = q.get(el.name);
    if (el.type === "radio") { if (v !== null) el.checked = el.value === v; else el.checked = el.defaultChecked; }
    else if (el.type === "checkbox") el.checked = v === null ? el.defaultChecked : v === "true";
    else if (el.tagName === "SELECT") el.value = v !== null ? v : (el.dataset.default || (el.options[0] || {}).value || "");
    else el.value = v !== null ? v : el.defaultValue;
  }
};

D.busy = function (on, el) {
  document.body.classList.toggle("busy", on);
  if (el) el.textContent = on ? D.t("working...") : "";
};

// Engineering notation with the unit: 1.6 kOhm, 3.3 nF, 97.9 us.
D.eng = function (v, unit, digits) {
  return D.localNum(D.engTyped(v, unit, digits));
};
// the same as typed into a field or a link (decimal point, "u" for micro): 1.6k
D.engTyped = function (v, unit, digits) {
  if (v === null || v === undefined || !isFinite(v)) return D.t("n/a");
  digits = digits || 4;
  if (v === 0) return `0 ${unit || ""}`.trim();
  const pre = [[1e12, "T"], [1e9, "G"], [1e6, "M"], [1e3, "k"], [1, ""], [1e-3, "m"], [1e-6, "u"], [1e-9, "n"],
               [1e-12, "p"], [1e-15, "f"]];
  const a = Math.abs(v);
  for (const [f, p] of pre) if (a >= f * 0.9995) return `${+(v / f).toPrecision(digits)} ${p}${unit || ""}`.trim();
  return `${v.toPrecision(digits)} ${unit || ""}`.trim();
};

// A number without a unit (a gain, a damping ratio): plain digits, never an SI prefix ("0.9887", not "988.7 m").
D.num = function (v, digits) {
  if (v === null || v === undefined || !isFinite(v)) return D.t("n/a");
  const a = Math.abs(v);
  return D.localNum(a !== 0 && (a < 1e-3 || a >= 1e6) ? (+v).toExponential((digits || 4) - 1) : String(+(+v).toPrecision(digits || 4)));
};

// A model's parameter as "name = value unit": the unit the name carries (tau_s, wn_rad_s) goes on the value.
D.param = function (name, v, digits) {
  const units = [[/_rad_s$/, "rad/s"], [/_hz$/i, "Hz"], [/_s$/, "s"], [/_ohm$/, "Ohm"], [/_f$/, "F"], [/_v$/i, "V"]];
  for (const [re, unit] of units) if (re.test(name)) return `${name.replace(re, "")} = ${D.eng(v, unit, digits || 4)}`;
  return `${name} = ${D.num(v, digits)}`;
};

// A check by its title: the plant's checks carry one; the PID's (design-pid --json) only an id.
D.CHECK_TITLES = {
  kp_accuracy: D.N_("Kp as built"), ti_accuracy: D.N_("Ti as built"), td_accuracy: D.N_("Td as built"),
  integrator_corner: D.N_("integrator corner"), differentiator_corner: D.N_("differentiator corner"),
  bandwidth_difference: D.N_("difference amplifier bandwidth"), bandwidth_inverter: D.N_("inverter bandwidth"),
  bandwidth_integrator: D.N_("integrator bandwidth"), bandwidth_summer: D.N_("summer bandwidth"), bandwidth_gain: D.N_("gain stage bandwidth"),
  bandwidth_differentiator: D.N_("differentiator bandwidth"), resistor_bounds: D.N_("resistors within their range"),
  capacitor_bounds: D.N_("capacitors within their range"), closed_loop_stable: D.N_("closed loop stable"),
  phase_margin: D.N_("phase margin"), steady_state_error: D.N_("steady-state error"), slew_rate: D.N_("op-amp slew rate"),
  output_swing: D.N_("op-amp output swing"),
};
D.checkTitle = function (c) {
  return D.t(c.title || D.CHECK_TITLES[c.id] || String(c.id || c.name || "").replace(/_/g, " "));
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

// A design's bill of materials as the page's language writes it (the answer's bom_text), its first 7 columns.
D.bomTable = function (p) {
  return D.table((p.bom_header || p.bom.header).slice(0, 7), (p.bom_text || p.bom.rows).map(x => x.slice(0, 7)));
};

D.checksTable = function (checks) {
  return D.table([D.t("check"), D.t("result"), D.t("detail")], checks.map(c => {
    const s = document.createElement("span");
    s.className = c.ok ? "ok" : "fail";
    s.textContent = c.ok ? D.t("ok") : D.t("FAILED");
    return [D.checkTitle(c), s, c.detail];
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

const COLOURS = ["#9467bd", "#8c564b", "#17becf", "#bcbd22", "#e377c2", "#7f7f7f"];
// One colour per kind of trace on every plot (issue 29: red was SPICE on one plot and the ideal op-amp on the
// next): SPICE red, the op-amp-aware model (and the realised loop) blue, the ideal one green, the measured data
// black, the plant alone grey, the tolerance band orange; the identified models take the other colours in turn.
D.TRACE_KINDS = [[/^mask/, "#6a3d9a"], [/^SPICE/, "#d62728"], [/^data$|integrated impulse/, "#111111"], [/^tolerance band/, "#e0a040"],
                 [/ideal/, "#2ca02c"], [/plant alone/, "#7f7f7f"], [/model|analytic|realised|loop gain/, "#1f77b4"]];
D.traceColour = function (label, i) {
  const kind = D.TRACE_KINDS.find(([re]) => re.test(label));
  return kind ? kind[1] : COLOURS[i % COLOURS.length];
};

// One interactive plot (uPlot): drag to zoom, double-click to reset, click a legend entry to hide its trace.
D.plot = function (el, trace, opts) {
  opts = opts || {};
  if (el._plot) { el._plot.destroy(); el._plot = null; }
  if (el._resize) { el._resize.disconnect(); el._resize = null; }
  el.innerHTML = "";
  const data = [trace.x, ...trace.series.map(s => s.y)];
  // as wide as its box (a phone's 390 px too), and redrawn at the box's width when that changes
  const width = Math.max(200, el.clientWidth || 640);
  // the legend's values as the page writes numbers (uPlot shows "--" for none: blank here)
  const series = [{label: trace.x_label, value: (u, v) => v === null || v === undefined ? "" : D.eng(v, opts.xUnit || "", 4)}];
  let others = 0;
  trace.series.forEach((s, i) => {
    const band = /^(tolerance band|mask)/.test(s.label);   // dashed: limits, not responses
    const points = /^(data|SPICE \.ac)$/.test(s.label);
    const kind = D.TRACE_KINDS.some(([re]) => re.test(s.label));
    // measured points as small rings, so the model lines under them stay visible
    series.push({label: s.text || s.label, stroke: D.traceColour(s.label, kind ? 0 : others++),
                 width: i === 0 && !band ? 2.5 : 1.5, dash: band ? [4, 4] : undefined,
                 value: (u, v) => v === null || v === undefined ? "" : D.num(v, 4),
                 spanGaps: false, points: points ? {show: true, size: 4, width: 1, fill: "transparent"} : {show: false},
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
    hooks: {draw: [u => D.drawMarks(u, opts.marks || [])]},
    legend: {live: true},
  }, data, el);
  el._plot = u;
  if (window.ResizeObserver) {
    el._resize = new ResizeObserver(() => {
      const w = Math.max(200, el.clientWidth);
      if (el._plot && Math.abs(w - el._plot.width) > 1) el._plot.setSize({width: w, height: el._plot.height});
    });
    el._resize.observe(el);
  }
  el.dataset.series = trace.series.map(s => s.label).join("|");
  el.dataset.marks = (opts.marks || []).map(m => m.label).join("|");
  D.plotText(el, trace, opts);
  return u;
};

// A plot's text alternative: what it shows in one line (its aria-label) and its key points as a table (a
// dozen points along x, each trace's value there; the marks), in a <details> under it.
D.plotText = function (el, trace, opts) {
  const yLabel = D.t(opts.yLabel || "value");
  el.setAttribute("role", "img");
  el.setAttribute("aria-label", D.t("{y} against {x}: {traces}", {y: yLabel, x: trace.x_label,
                                                                  traces: trace.series.map(s => s.text || s.label).join(", ")}) +
                  ((opts.marks || []).length ? D.t("; marked: {marks}", {marks: opts.marks.map(m => m.label).join(", ")}) : ""));
  const n = trace.x.length, rows = [];
  for (let k = 0; k < 12 && n; k++) {
    const i = Math.round(k * (n - 1) / 11);
    if (rows.length && rows[rows.length - 1].i === i) continue;
    rows.push({i, cells: [D.eng(trace.x[i], opts.xUnit || "", 4),
                          ...trace.series.map(s => s.y[i] === null || s.y[i] === undefined ? "" : D.num(s.y[i], 4))]});
  }
  const table = D.table([trace.x_label, ...trace.series.map(s => s.text || s.label)], rows.map(r => r.cells));
  const marks = (opts.marks || []).map(m => { const p = document.createElement("p"); p.textContent = m.label; return p; });
  let details = el.nextElementSibling;
  if (!details || !details.classList.contains("plot-text")) {
    details = document.createElement("details");
    details.className = "plot-text";
    el.after(details);
  }
  details.replaceChildren(Object.assign(document.createElement("summary"), {textContent: D.t("{y}: key points as a table", {y: yLabel})}),
                          ...marks, Object.assign(document.createElement("div"), {className: "scroll"}));
  details.lastChild.append(table);
};

// The schematic (SVG, drawn by the server): a text alternative naming its parts, and a button that opens it
// full size in a tab of its own, where the browser zooms it as any SVG.
D.schematic = function (el, svg, what) {
  el.innerHTML = svg;
  D.translatePage(el);   // its labels ("generator") in the page's language
  const img = el.querySelector("svg");
  if (img) {
    img.setAttribute("role", "img");
    img.setAttribute("aria-label", what);
  }
  let open = el.parentElement.querySelector(".open-full");
  if (!open) {
    open = document.createElement("button");
    open.type = "button";
    open.className = "open-full";
    open.textContent = D.t("open the schematic full size");
    el.after(open);
  }
  open.onclick = () => {
    const url = URL.createObjectURL(new Blob([svg], {type: "image/svg+xml"}));
    if (!window.open(url, "_blank")) D.download(new Blob([svg], {type: "image/svg+xml"}), "schematic.svg");
  };
};

// Vertical marks on a plot ({x, label}: the crossover, the phase-crossover, the sensitivity peak), drawn over the
// traces with their label at the top, each label a line lower than the one before (marks a few percent apart in
// frequency, as a loop's crossover and its sensitivity peak often are, would print over each other); one off the
// axis's range is left out (zoomed away).
D.drawMarks = function (u, marks) {
  const ctx = u.ctx, top = u.bbox.top, bottom = u.bbox.top + u.bbox.height;
  ctx.save();
  ctx.font = `${Math.round(11 * devicePixelRatio)}px system-ui, sans-serif`;
  ctx.fillStyle = ctx.strokeStyle = "#555";
  ctx.textAlign = "left";          // (uPlot leaves its axes' alignment set)
  ctx.textBaseline = "top";
  ctx.setLineDash([5 * devicePixelRatio, 4 * devicePixelRatio]);
  ctx.lineWidth = devicePixelRatio;
  let row = 0;
  for (const m of marks) {
    if (!isFinite(m.x) || m.x < u.scales.x.min || m.x > u.scales.x.max) continue;
    const x = Math.round(u.valToPos(m.x, "x", true));
    ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, bottom); ctx.stroke();
    ctx.fillText(m.label, x + 4 * devicePixelRatio, top + (2 + 14 * row++) * devicePixelRatio);
  }
  ctx.restore();
};

D.nav = function (current) {
  const nav = document.querySelector("nav");
  const keep = D.lang !== "en" ? `?lang=${D.lang}` : "";
  for (const [href, text] of [["/plant", D.t("Plant")], ["/pid", D.t("PID")], ["/filter", D.t("Filter")],
                              ["/identify", D.t("Identify")], ["/check", D.t("Check")]]) {
    const a = document.createElement("a");
    a.href = href + keep; a.textContent = text;
    if (href === current) a.className = "here";
    nav.append(a);
  }
  // the language menu: the page again in the language chosen, its inputs kept (the address has them)
  const menu = document.createElement("select");
  menu.id = "lang";
  menu.setAttribute("aria-label", "language / idioma");
  menu.setAttribute("translate", "no");
  for (const [code, name] of Object.entries(D.LANGUAGES)) menu.append(new Option(name, code, false, code === D.lang));
  menu.addEventListener("change", () => {
    const q = new URLSearchParams(location.search);
    q.set("lang", menu.value);
    location.search = q.toString();
  });
  nav.append(menu);
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

// The tolerance panel (Plant, PID): the yield with its 95 % interval, the part to buy tighter, and each
// histogram (the server's bins: D.histogram) with its limits; hidden without a Monte Carlo.
D.pct = v => D.localNum(`${(100 * v).toPrecision(3)} %`);
// A Monte Carlo figure's value with its unit (the histogram's, from the library's title table): engineering
// notation for Hz and s, else the number and the unit; the title carries no unit (issue 29).
D.figureValue = function (v, unit) {
  if (unit === "Hz" || unit === "s") return D.eng(v, unit, 4);
  return unit && v !== null && v !== undefined && isFinite(v) ? `${D.num(v, 4)} ${unit}` : D.num(v, 4);
};
D.tolerance = function (mc, hists) {
  const shown = Object.fromEntries((hists || []).map(h => [h.figure, h]));
  const title = name => (shown[name] && shown[name].title) || name;
  const value = (name, v) => D.figureValue(v, shown[name] && shown[name].unit);
  const section = document.getElementById("tolerance-section");
  if (!section) return;
  section.hidden = !mc;
  if (!mc) return;
  const figs = [D.fig(D.t("builds drawn"), String(mc.settings.samples))];
  const y = mc.yield;
  if (y && mc.limits && mc.limits.length) {
    figs.push(D.fig(D.t("yield"), D.pct(y.fraction)),
              D.fig(D.t("95 % interval (Wilson)"), D.t("{lo} to {hi}", {lo: D.pct(y.ci95[0]), hi: D.pct(y.ci95[1])})),
              D.fig(D.t("within"), mc.limits.map(l => `${title(l.figure)} ${D.t("{lo} to {hi}", {lo: value(l.figure, l.min), hi: value(l.figure, l.max)})}`).join("; ")));
  } else figs.push(D.fig(D.t("yield"), D.t("no limits given: the spread alone")));
  document.getElementById("yield").replaceChildren(...figs);
  const t = mc.tighten, tight = document.getElementById("tighten");
  tight.textContent = !t ? "" : t.yield > t.yield_now
    ? D.t("Buy {part} tighter: at {tol} % the yield is {yield} (now {now}).",
          {part: t.part, tol: D.localNum(String(t.tolerance_pct)), yield: D.pct(t.yield), now: D.pct(t.yield_now)})
    : D.t("No part bought tighter raises the yield: the design, not the parts, limits it.");
  const box = document.getElementById("histograms");
  box.replaceChildren(...(hists || []).map(h => D.histogram(h)));
};

// A histogram as SVG (bars, the limits as red lines, the nominal dashed), zoomable as any SVG, with its text
// alternative: the counts per bin in a table below.
D.histogram = function (h) {
  const name = h.title ? (h.unit ? `${h.title} (${h.unit})` : h.title) : h.figure;   // "fn (Hz)": the unit on the axis
  const value = v => D.figureValue(v, h.unit);
  const W = 640, H = 200, pad = 30, ns = "http://www.w3.org/2000/svg";
  const lo = Math.min(h.edges[0], h.min ?? Infinity, h.nominal ?? Infinity);
  const hi = Math.max(h.edges[h.edges.length - 1], h.max ?? -Infinity, h.nominal ?? -Infinity);
  const span = hi - lo || Math.abs(hi) || 1, top = Math.max(...h.counts, 1);
  const x = v => pad + (W - 2 * pad) * (v - lo + 0.03 * span) / (1.06 * span);
  const yv = c => H - pad - (H - 2 * pad) * c / top;
  const svg = document.createElementNS(ns, "svg");
  svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
  svg.setAttribute("role", "img");
  svg.setAttribute("class", "histogram");
  svg.setAttribute("aria-label", D.t("histogram of {figure} over {n} builds", {figure: name, n: h.n}) +
                   (h.min !== null ? D.t(", limits {lo} to {hi}", {lo: value(h.min), hi: value(h.max)}) : ""));
  const el = (name, attrs, text) => {
    const e = document.createElementNS(ns, name);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
    if (text) e.textContent = text;
    svg.append(e);
  };
  h.counts.forEach((c, i) => el("rect", {x: x(h.edges[i]), y: yv(c), width: Math.max(0.5, x(h.edges[i + 1]) - x(h.edges[i]) - 0.5),
                                         height: H - pad - yv(c), fill: "#6b8fc7"}));
  el("line", {x1: pad, x2: W - pad, y1: H - pad, y2: H - pad, stroke: "#555"});
  for (const [v, what] of [[h.min, "min"], [h.max, "max"]]) if (v !== null && v !== undefined)
    el("line", {x1: x(v), x2: x(v), y1: pad / 2, y2: H - pad, stroke: "#d62728", "stroke-width": 2, "data-limit": what});
  if (h.nominal !== null && h.nominal !== undefined)
    el("line", {x1: x(h.nominal), x2: x(h.nominal), y1: pad / 2, y2: H - pad, stroke: "#333", "stroke-dasharray": "4 3"});
  el("text", {x: pad, y: H - 8, "font-size": 11}, value(lo));
  el("text", {x: W - pad, y: H - 8, "font-size": 11, "text-anchor": "end"}, value(hi));
  el("text", {x: W / 2, y: 12, "font-size": 12, "text-anchor": "middle"}, D.t("{figure} over {n} builds", {figure: name, n: h.n}));
  const wrap = document.createElement("figure");
  wrap.className = "histogram-figure";
  wrap.dataset.figure = h.figure;
  wrap.append(svg);
  const details = document.createElement("details");
  details.append(Object.assign(document.createElement("summary"), {textContent: D.t("{figure}: the counts as a table", {figure: name})}),
                 D.table([D.t("from"), D.t("to"), D.t("builds")], h.counts.map((c, i) => [value(h.edges[i]), value(h.edges[i + 1]), c])));
  wrap.append(details);
  return wrap;
};

// The build sheet's content on the page: our own HTML (the sheet's renderer escapes every text), in a shadow root
// so its styles stay inside; its advice in the page's words (the printed sheet keeps the command's: it goes with
// the bundle's files).
D.sheet = function (host, html, form) {
  const root = host.shadowRoot || host.attachShadow({mode: "open"});
  root.innerHTML = html;
  const walk = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  for (let n = walk.nextNode(); n; n = walk.nextNode()) {
    if (n.textContent.includes("--")) n.textContent = D.inPageWords(form, n.textContent, true);
  }
};
