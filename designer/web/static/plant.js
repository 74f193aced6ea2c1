// The plant page: the form's options go to POST /api/plant?view=page as they change (debounced); the
// answer is design-plant's JSON with the plots' data, the schematic (SVG), the bench settings and the BOM.
"use strict";
D.nav("/plant");
const form = document.getElementById("form");
const status = document.getElementById("status");
let seq = 0, last = null;

function show(answer) {
  const r = answer.result, p = answer.page, b = r.built;
  document.getElementById("title").textContent = p.title;
  const figs = document.getElementById("figures");
  figs.replaceChildren(
    D.fig("R1", D.eng(b.R1_ohm, "Ohm", 3)), D.fig("R2", D.eng(b.R2_ohm, "Ohm", 3)),
    D.fig("C1", D.eng(b.C1_f, "F", 3)), D.fig("C2", D.eng(b.C2_f, "F", 3)),
    D.fig(D.t("fn as built ({opamp})", {opamp: r.opamp.name}), D.eng(b.fn_opamp_hz, "Hz", 4)),
    D.fig(D.t("zeta as built ({opamp})", {opamp: r.opamp.name}), D.num(b.zeta_opamp, 4)),
    D.fig(D.t("overshoot (model)"), D.localNum(`${r.analytic_opamp.overshoot_pct.toPrecision(4)} %`)),
    D.fig(D.t("overshoot (SPICE)"), r.spice ? D.localNum(`${r.spice.overshoot_pct.toPrecision(4)} %`) : D.t("not simulated")),
    D.fig(D.t("peak time"), D.eng((r.spice || r.analytic_opamp).peak_time_s, "s", 4)),
    D.fig(D.t("settling time (2 %)"), D.eng((r.spice || r.analytic_opamp).settling_time_s, "s", 4)),
    D.fig(D.t("SPICE agrees with the model"), r.comparison.pass === undefined ? D.t("n/a") : (r.comparison.pass ? D.t("yes") : D.t("NO"))));
  document.getElementById("notes").replaceChildren(...r.notes.map(n => { const e = document.createElement("p"); e.textContent = D.inPageWords(form, D.localNum(n)); return e; }));
  D.schematic(document.getElementById("schematic"), p.schematic_svg,
              D.t("schematic: {parts}", {parts: p.bom.rows.map(x => `${x[0]} ${D.localNum(x[1])}`).join(", ")}));
  document.getElementById("bench").replaceChildren(D.table([D.t("set"), D.t("to")], p.bench));
  document.getElementById("bomtable").replaceChildren(D.table((p.bom_header || p.bom.header).slice(0, 7), (p.bom_text || p.bom.rows).map(x => x.slice(0, 7))));
  document.getElementById("checks").replaceChildren(D.checksTable(p.checks || r.checks));
  D.tolerance(r.monte_carlo, p.histograms);
  D.sheet(document.getElementById("sheet-html"), p.sheet_html, form);
  D.plot(document.getElementById("step"), p.step, {xUnit: "s", yLabel: D.t("output (V)")});
  D.plot(document.getElementById("bode-gain"), p.bode.gain, {xUnit: "Hz", yLabel: D.t("gain (dB)"), height: 240});
  D.plot(document.getElementById("bode-phase"), p.bode.phase, {xUnit: "Hz", yLabel: D.t("phase (deg)"), height: 200});
}

async function design() {
  const mine = ++seq;
  const opts = D.options(form);
  D.markStale("pending");
  D.busy(true, status);
  const r = await D.api("/api/plant?view=page", opts, false, "form");
  if (r.aborted || mine !== seq) return;          // a newer request is on its way: this answer is stale
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); D.answered("error"); return; }
  D.clearError(form);
  last = {opts, answer: r.data};   // the downloads are of these inputs (D.answered turns them on)
  D.remember(opts);
  show(r.data);
  status.textContent = D.t("designed and simulated ({simulator})", {simulator: r.data.result.simulator || D.t("no simulator")});
  D.answered("done");
}

async function file(kind) {
  if (!last || D.isStale()) return;
  if (kind === "bom") {
    D.download(new Blob([last.answer.page.bom_csv], {type: "text/csv"}), "bom.csv");
    return;
  }
  D.busy(true, status);
  const r = await D.api(`/api/plant/${kind}`, last.opts, true);
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); return; }
  // the sheet in a new tab to print; a browser that blocks the tab gets it as a file
  if (kind === "sheet") { if (!window.open(URL.createObjectURL(r.blob), "_blank")) D.download(r.blob, "build-sheet.html"); }
  else D.download(r.blob, r.filename || "plant.zip");   // the design's name, as design-plant names it
}

(async function () {
  const c = await D.loadChoices();
  for (const s of form.querySelectorAll("select[data-choices]")) D.fill(s, c[s.dataset.choices], s.dataset.default);
  D.fillFromQuery(form);
  D.liveForm(form, design, () => JSON.stringify(D.options(form)));
  document.getElementById("sheet").onclick = () => file("sheet");
  document.getElementById("bundle").onclick = () => file("bundle");
  document.getElementById("bom").onclick = () => file("bom");
  document.getElementById("topid").onclick = () => {
    if (!last || D.isStale()) return;
    const o = last.opts, b = last.answer.result.built;
    // the plant as built, by its parts: the PID is designed for the circuit on the bench
    const code = v => D.engTyped(v, "", 6).replace(" ", "");   // 1.6k, 3.3n: engineering notation as typed
    const q = new URLSearchParams({"plant": "parts", "plant-r1": code(b.R1_ohm), "plant-r2": code(b.R2_ohm),
                                   "plant-c1": code(b.C1_f), "plant-c2": code(b.C2_f), "opamp": o.opamp || "LM741"});
    if (D.lang !== "en") q.set("lang", D.lang);
    if (b.gain !== 1) q.set("plant-gain", b.gain);
    location.href = "/pid?" + q.toString();
  };
  design();
})();
