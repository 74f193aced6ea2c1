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
  for (const id of ["format", "methods", "loop"]) document.getElementById(id).replaceChildren();
  for (const id of ["plot", "phase"]) {
    const el = document.getElementById(id);
    if (el._plot) { el._plot.destroy(); el._plot = null; }
    el.replaceChildren();
  }
};

function show(answer) {
  const r = answer.result, p = answer.page;
  const cap = r.capture || {};
  const fmt = r.format === "frequency-table" ? "frequency table (analysed as identify-freq does)" :
    r.format === "broadband" ? `${cap.format}, broadband input (${r.excitation.kind}: ${r.method} analysis)` : cap.format;
  document.getElementById("format").innerHTML = "";
  const line = document.createElement("p");
  line.id = "format-line";
  line.textContent = `Format: ${fmt}` + (cap.samples ? `, ${cap.samples} samples` : "") +
    (cap.output ? `, output ${cap.output}` : "") + (cap.input ? `, input ${cap.input}` : ", no input column");
  document.getElementById("format").append(line);
  const best = r.best;
  const b = document.createElement("p");
  b.id = "best";
  b.innerHTML = "<b>Best model:</b> ";
  b.append(best ? `${best.name} (${best.model}): ${params(best.params)}` : "none valid");
  document.getElementById("format").append(b);
  // a loop gain's table: what it is for, its crossover and margins, among the figures and marked on its plots
  const loop = r.loop, marks = [];
  const loopBox = document.getElementById("loop");
  loopBox.replaceChildren();
  if (loop) {
    const deg = v => v === null || v === undefined ? "not reached" : `${(+v).toFixed(1)} deg`;
    const db = v => v === null || v === undefined ? "not reached" : `${(+v).toFixed(1)} dB`;
    loopBox.append(D.fig("gain crossover", D.eng(loop.crossover_hz, "Hz", 3)), D.fig("phase margin", deg(loop.phase_margin_deg)),
                   D.fig("gain margin", db(loop.gain_margin_db)), D.fig("phase crossover", D.eng(loop.phase_crossover_hz, "Hz", 3)));
    loopBox.setAttribute("aria-label", "loop gain margins");
    b.replaceChildren(Object.assign(document.createElement("b"), {textContent: "A loop gain (open loop): "}),
                      `its margins above; best model ${best ? `${best.name} (${best.model}): ${params(best.params)}` : "none valid"}`);
    marks.push({x: loop.crossover_hz, label: `crossover, PM ${deg(loop.phase_margin_deg)}`});
    if (loop.phase_crossover_hz) marks.push({x: loop.phase_crossover_hz, label: `GM ${db(loop.gain_margin_db)}`});
  }
  const ph = document.getElementById("phase");
  if (p.kind === "step") {
    D.plot(document.getElementById("plot"), p.plot, {xUnit: "s", yLabel: cap.output || "output"});
    if (ph._plot) { ph._plot.destroy(); ph._plot = null; } ph.innerHTML = "";
  } else if (p.kind === "frequency") {
    D.plot(document.getElementById("plot"), p.plot, {xUnit: "Hz", yLabel: "gain (dB)", marks});
    if (p.phase) D.plot(ph, p.phase, {xUnit: "Hz", yLabel: "phase (deg)", height: 220, marks});
  } else {   // broadband: the integrated impulse response and the spectral estimate's gain
    const unit = t => t.log_x ? ["Hz", "gain (dB)"] : ["s", cap.output || "output"];
    if (p.plot) D.plot(document.getElementById("plot"), p.plot, {xUnit: unit(p.plot)[0], yLabel: unit(p.plot)[1]});
    if (p.second) D.plot(ph, p.second, {xUnit: "Hz", yLabel: "gain (dB)", height: 240});
  }
  document.getElementById("methods").replaceChildren(D.table(
    ["#", "method", "model", "parameters", "IAE", "valid", "note"],
    r.methods.map((m, i) => [i + 1, m.name, m.model, params(m.params), m.iae === null ? "" : (+m.iae).toPrecision(3),
                             m.valid ? "yes" : "no", D.inPageWords(form, m.note || "")])));
}

async function identify() {
  if (!file) return;
  const mine = ++seq;
  const q = new URLSearchParams({view: "page", filename: file.name});
  for (const [k, v] of Object.entries(D.options(form))) q.set(k, v === true ? "true" : v);
  D.markStale("pending");
  D.busy(true, status);
  const r = await D.api(`/api/identify?${q}`, file, false, "form");
  if (r.aborted || mine !== seq) return;
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); D.answered("error"); return; }
  D.clearError(form);
  last = r.data;
  show(r.data);
  status.textContent = `identified ${file.name}`;
  D.answered("done");
  document.getElementById("topid").disabled = !r.data.result.best;   // a PID needs a valid model
}

(async function () {
  const c = await D.loadChoices();
  D.fill(form.querySelector("select[name=format]"), ["", ...c.formats], "");
  form.querySelector("select[name=format]").options[0].textContent = "auto";
  D.dropZone(document.getElementById("drop"), document.getElementById("file"), files => { file = files[0]; identify(); });
  D.liveForm(form, identify, () => file ? JSON.stringify([file.name, file.size, file.lastModified, D.options(form)]) : null);
  document.getElementById("topid").onclick = () => {
    if (!last) return;
    sessionStorage.setItem("identify-result", JSON.stringify(last.result));
    location.href = "/pid?plant=identify";
  };
})();
