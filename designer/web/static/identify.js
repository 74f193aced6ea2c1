// The identify page: a dropped capture goes as the body of POST /api/identify?view=page (its options in
// the query string); the answer is identify's JSON with the data and the best models' traces.
"use strict";
D.nav("/identify");
const form = document.getElementById("form");
const status = document.getElementById("status");
let file = null, seq = 0, last = null;

function params(p) {
  return Object.entries(p || {}).map(([k, v]) => D.param(k, v)).join(", ");
}

// a refused input leaves no model to read nor to design a PID for: the previous capture's are cleared
D.onStale = function (why) {
  if (why !== "refused") return;
  last = null;
  for (const id of ["format", "methods", "loop", "candidates"]) document.getElementById(id).replaceChildren();
  document.getElementById("candidates-box").hidden = true;
  for (const id of ["plot", "phase", "record"]) {
    const el = document.getElementById(id);
    if (el._plot) { el._plot.destroy(); el._plot = null; }
    el.replaceChildren();
  }
};

// where the validation part of a record starts, marked on its plot
function split(trace) {
  const x = trace.validation_start_s;
  return x === null || x === undefined ? [] : [{x, label: D.t("validation from here")}];
}

function show(answer) {
  const r = answer.result, p = answer.page;
  const cap = r.capture || {};
  const fmt = r.format === "frequency-table" ? D.t("frequency table (analysed as identify-freq does)") :
    r.format === "broadband" ? D.t("{format}, broadband input ({kind}: {method} analysis)",
                                   {format: cap.format, kind: r.excitation.kind, method: r.method}) : cap.format;
  document.getElementById("format").innerHTML = "";
  const line = document.createElement("p");
  line.id = "format-line";
  line.textContent = D.t("Format: {format}", {format: fmt}) + (cap.samples ? D.t(", {n} samples", {n: cap.samples}) : "") +
    (cap.output ? D.t(", output {name}", {name: cap.output}) : "") +
    (cap.input ? D.t(", input {name}", {name: cap.input}) : D.t(", no input column"));
  document.getElementById("format").append(line);
  const best = r.best;
  const b = document.createElement("p");
  b.id = "best";
  b.replaceChildren(Object.assign(document.createElement("b"), {textContent: D.t("Best model:")}), " ");
  // an input only the output-error fit reads has no route ranking of its own: its best is the validation's
  const vbest = r.validation && r.validation.best;
  b.append(best ? `${best.name} (${best.model}): ${params(best.params)}` :
           vbest ? `${vbest.route} ${vbest.name} (${vbest.model}): ${params(vbest.params)}` : D.t("none valid"));
  document.getElementById("format").append(b);
  // a loop gain's table: what it is for, its crossover and margins, among the figures and marked on its plots
  const loop = r.loop, marks = [];
  const loopBox = document.getElementById("loop");
  loopBox.replaceChildren();
  if (loop) {
    const deg = v => v === null || v === undefined ? D.t("not reached") : D.localNum(`${(+v).toFixed(1)} deg`);
    const db = v => v === null || v === undefined ? D.t("not reached") : D.localNum(`${(+v).toFixed(1)} dB`);
    loopBox.append(D.fig(D.t("gain crossover"), D.eng(loop.crossover_hz, "Hz", 3)), D.fig(D.t("phase margin"), deg(loop.phase_margin_deg)),
                   D.fig(D.t("gain margin"), db(loop.gain_margin_db)), D.fig(D.t("phase crossover"), D.eng(loop.phase_crossover_hz, "Hz", 3)));
    loopBox.setAttribute("aria-label", D.t("loop gain margins"));
    b.replaceChildren(Object.assign(document.createElement("b"), {textContent: D.t("A loop gain (open loop):") + " "}),
                      D.t("its margins above; best model {model}",
                          {model: best ? `${best.name} (${best.model}): ${params(best.params)}` : D.t("none valid")}));
    marks.push({x: loop.crossover_hz, label: D.t("crossover, PM {pm}", {pm: deg(loop.phase_margin_deg)})});
    if (loop.phase_crossover_hz) marks.push({x: loop.phase_crossover_hz, label: D.t("GM {gm}", {gm: db(loop.gain_margin_db)})});
  }
  const ph = document.getElementById("phase");
  if (p.kind === "step") {
    D.plot(document.getElementById("plot"), p.plot, {xUnit: "s", yLabel: cap.output || D.t("output")});
    if (ph._plot) { ph._plot.destroy(); ph._plot = null; } ph.innerHTML = "";
  } else if (p.kind === "frequency") {
    D.plot(document.getElementById("plot"), p.plot, {xUnit: "Hz", yLabel: D.t("gain (dB)"), marks});
    if (p.phase) D.plot(ph, p.phase, {xUnit: "Hz", yLabel: D.t("phase (deg)"), height: 220, marks});
  } else {   // broadband: the integrated impulse response and the spectral estimate's gain
    const unit = t => t.log_x ? ["Hz", D.t("gain (dB)")] : ["s", cap.output || D.t("output")];
    if (p.plot) D.plot(document.getElementById("plot"), p.plot, {xUnit: unit(p.plot)[0], yLabel: unit(p.plot)[1], marks: split(p.plot)});
    if (p.second) D.plot(ph, p.second, {xUnit: "Hz", yLabel: D.t("gain (dB)"), height: 240});
  }
  // the record with its best models simulated under the recorded input (the plot itself for an input only
  // the output-error fit reads), and every route's models with their validation fit and why not valid
  const rec = document.getElementById("record");
  if (rec._plot) { rec._plot.destroy(); rec._plot = null; } rec.replaceChildren();
  if (p.record) D.plot(rec, p.record, {xUnit: "s", yLabel: cap.output || D.t("output"), height: 260, marks: split(p.record)});
  const cands = p.candidates || [];
  document.getElementById("candidates-box").hidden = !cands.length;
  document.getElementById("candidates").replaceChildren(...(cands.length ? [D.table(
    [D.t("route"), D.t("method"), D.t("model"), D.t("validation fit"), D.t("valid"), D.t("why not")],
    cands.map(c => [c.route, c.method, c.model, c.fit_percent === null ? "" : D.localNum(`${(+c.fit_percent).toFixed(1)} %`),
                    c.valid ? D.t("yes") : D.t("no"), D.inPageWords(form, c.note || "")]))] : []));
  document.getElementById("methods").replaceChildren(D.table(
    ["#", D.t("method"), D.t("model"), D.t("parameters"), "IAE", D.t("valid"), D.t("note")],
    (r.methods || []).map((m, i) => [i + 1, m.name, m.model, params(m.params), m.iae === null ? "" : D.localNum((+m.iae).toPrecision(3)),
                             m.valid ? D.t("yes") : D.t("no"), D.inPageWords(form, m.note || "")])));
}

async function identify() {
  if (!file) return;
  const mine = ++seq;
  const q = new URLSearchParams({view: "page", filename: file.name});
  for (const [k, v] of Object.entries(D.options(form))) q.set(k, v === true ? "true" : v);
  if (D.lang !== "en") q.set("lang", D.lang);   // the page's words (its plots' names) in its language
  D.markStale("pending");
  D.busy(true, status);
  const r = await D.api(`/api/identify?${q}`, file, false, "form");
  if (r.aborted || mine !== seq) return;
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); D.answered("error"); return; }
  D.clearError(form);
  last = r.data;
  show(r.data);
  status.textContent = D.t("identified {file}", {file: file.name});
  D.answered("done");
  document.getElementById("topid").disabled = !r.data.result.best;   // a PID needs a valid model
}

(async function () {
  // a file chosen at once is taken at once (the format's menu, "auto" until it is filled, is auto)
  D.dropZone(document.getElementById("drop"), document.getElementById("file"), files => { file = files[0]; identify(); });
  D.liveForm(form, identify, () => file ? JSON.stringify([file.name, file.size, file.lastModified, D.options(form)]) : null);
  const c = await D.loadChoices();
  D.fill(form.querySelector("select[name=format]"), ["", ...c.formats], "");
  form.querySelector("select[name=format]").options[0].textContent = D.t("auto");
  document.getElementById("topid").onclick = () => {
    if (!last) return;
    sessionStorage.setItem("identify-result", JSON.stringify(last.result));
    location.href = "/pid?plant=identify" + (D.lang !== "en" ? `&lang=${D.lang}` : "");
  };
})();
