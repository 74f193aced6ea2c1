// The plant page: the form's options go to POST /api/plant?view=page as they change (debounced); the
// answer is design-plant's JSON with the plots' data, the schematic (SVG), the bench settings and the BOM.
"use strict";
D.nav("/plant");
const form = document.getElementById("form");
const status = document.getElementById("status");

const SEED_TOPOLOGY = "sallen-key-lowpass";   // the seed's circuit: its own pipeline (step, bench, schematic)
let topologies = [];

// The plant's transfer function by the section's response and order (the heading once showed the low-pass's
// whatever section was chosen): the target's fn (wn = 2 pi fn), zeta and gain K in the section's form.
const PLANT_TF = {
  "lowpass 2": "K wn² / (s² + 2 ζ wn s + wn²)", "highpass 2": "K s² / (s² + 2 ζ wn s + wn²)",
  "bandpass 2": "K 2 ζ wn s / (s² + 2 ζ wn s + wn²)", "lowpass 1": "K wn / (s + wn)", "highpass 1": "K s / (s + wn)",
};

// The chosen topology's declared parts (designator, R or C, role), as the registry lists them; a first-order
// section takes no zeta (its field hidden: not sent).
function showTopology() {
  const name = form.elements["topology"].value;
  const topo = topologies.find(t => t.name === name);
  if (!topo) return;
  const tf = PLANT_TF[`${topo.kind} ${topo.order}`];
  if (tf) document.getElementById("plant-tf").textContent = D.t("Plant: T(s) = {tf}", {tf});
  const zeta = form.elements["zeta"].closest("label");
  zeta.hidden = topo.order === 1;
  document.getElementById("topology-parts").replaceChildren(
    D.table([D.t("part"), D.t("kind"), D.t("role")], topo.parts.map(x => [x.ref, x.kind === "R" ? D.t("resistor")
                                                                                    : D.t("capacitor"), D.t(x.role)])));
}
D.onRestore = showTopology;

// A plant on another registered section (the generic pipeline): its declared parts, both models' figures, its
// step after the bench's rising edge (both models and the tolerance band) and Bode plot, its schematic, the
// bench's generator and scope, the BOM, checks and sheet.
function showCircuit(answer) {
  const r = answer.result, p = answer.page, o = r.built.opamp, i = r.built.ideal;
  document.getElementById("title").textContent = p.title;
  const spice = r.checks.find(c => c.id === "spice_agreement");
  document.getElementById("figures").replaceChildren(
    ...p.parts.map(x => D.fig(`${x.ref} (${D.t(x.role)})`, D.eng(x.value, x.kind === "R" ? "Ohm" : "F", 3))),
    D.fig(D.t("fn as built ({amp})", {amp: r.opamp.name}), D.eng(o.fn_hz, "Hz", 4)),
    ...(o.zeta === null ? [] : [D.fig(D.t("zeta as built ({amp})", {amp: r.opamp.name}), D.num(o.zeta, 4))]),
    D.fig(D.t("gain"), D.num(i.gain, 4)),
    D.fig(D.t("-3 dB frequency ({amp})", {amp: r.opamp.name}), o.f3db_hz.map(v => D.eng(v, "Hz", 4)).join(", ")),
    D.fig(D.t("SPICE agrees with the model"), !spice ? D.t("not simulated") : (spice.ok ? D.t("yes") : D.t("NO"))));
  document.getElementById("notes").replaceChildren(...(p.notes || r.notes).map(n => { const e = document.createElement("p"); e.textContent = D.inPageWords(form, n); return e; }));
  D.schematic(document.getElementById("schematic"), p.schematic_svg,
              D.t("schematic: {parts}", {parts: p.bom.rows.map(x => `${x[0]} ${D.localNum(x[1])}`).join(", ")}));
  document.getElementById("bench").replaceChildren(D.table([D.t("set"), D.t("to")], p.bench || []));
  document.getElementById("bomtable").replaceChildren(D.bomTable(p));
  document.getElementById("checks").replaceChildren(D.checksTable(p.checks || r.checks));
  D.tolerance(r.monte_carlo, p.histograms);
  D.sheet(document.getElementById("sheet-html"), p.sheet_html, form);
  if (p.step) D.plot(document.getElementById("step"), p.step, {xUnit: "s", yLabel: D.t("output (V)")});
  D.plot(document.getElementById("bode-gain"), p.bode.gain, {xUnit: "Hz", yLabel: D.t("gain (dB)"), height: 240});
  D.plot(document.getElementById("bode-phase"), p.bode.phase, {xUnit: "Hz", yLabel: D.t("phase (deg)"), height: 200});
}

function show(answer) {
  const seed = (answer.result.topology || SEED_TOPOLOGY) === SEED_TOPOLOGY;
  document.getElementById("step-section").hidden = !seed && !answer.page.step;
  if (!seed) { showCircuit(answer); return; }
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
  document.getElementById("bomtable").replaceChildren(D.bomTable(p));
  document.getElementById("checks").replaceChildren(D.checksTable(p.checks || r.checks));
  D.tolerance(r.monte_carlo, p.histograms);
  D.sheet(document.getElementById("sheet-html"), p.sheet_html, form);
  D.plot(document.getElementById("step"), p.step, {xUnit: "s", yLabel: D.t("output (V)")});
  D.plot(document.getElementById("bode-gain"), p.bode.gain, {xUnit: "Hz", yLabel: D.t("gain (dB)"), height: 240});
  D.plot(document.getElementById("bode-phase"), p.bode.phase, {xUnit: "Hz", yLabel: D.t("phase (deg)"), height: 200});
}

const page = D.designPage(form, status, "/api/plant", show,
                          r => D.t("designed and simulated ({simulator})", {simulator: r.result.simulator || D.t("no simulator")}));

(async function () {
  const c = await D.loadChoices();
  for (const s of form.querySelectorAll("select[data-choices]")) D.fill(s, c[s.dataset.choices], s.dataset.default);
  topologies = c.topologies;
  const menu = form.elements["topology"];
  D.fill(menu, topologies.map(t => t.name), SEED_TOPOLOGY);
  for (const o of menu.options) o.textContent = D.t(topologies.find(t => t.name === o.value).title);
  D.fillFromQuery(form);
  showTopology();
  form.addEventListener("change", e => { if (e.target === menu) showTopology(); }, true);   // before it asks
  const live = D.liveForm(form, page.design, () => JSON.stringify(D.options(form)));
  document.getElementById("sheet").onclick = () => page.file("sheet");
  document.getElementById("bundle").onclick = () => page.file("bundle");
  document.getElementById("bom").onclick = () => page.file("bom");
  document.getElementById("topid").onclick = () => {
    const last = page.shown();
    if (!last || D.isStale()) return;
    const o = last.opts, r = last.answer.result, b = r.built;
    // the plant as built, by its parts: the PID is designed for the circuit on the bench
    const code = v => D.engTyped(v, "", 6).replace(" ", "");   // 1.6k, 3.3n: engineering notation as typed
    const seed = (r.topology || SEED_TOPOLOGY) === SEED_TOPOLOGY;
    const q = new URLSearchParams(seed ? {"plant": "parts", "plant-r1": code(b.R1_ohm), "plant-r2": code(b.R2_ohm),
                                          "plant-c1": code(b.C1_f), "plant-c2": code(b.C2_f)}
                                       // another section: its declared parts by designator, items apart as typed
                                       : {"plant": "parts", "plant-topology": r.topology,
                                          "plant-part": Object.entries(r.parts).map(([ref, x]) => `${ref}=${code(x.value)}`).join(" ")});
    q.set("opamp", o.opamp || "LM741");
    if (D.lang !== "en") q.set("lang", D.lang);
    if (seed && b.gain !== 1) q.set("plant-gain", b.gain);
    location.href = "/pid?" + q.toString();
  };
  live.now();   // (through the form: typing back to these inputs asks nothing)
})();
