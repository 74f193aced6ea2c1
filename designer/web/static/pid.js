// The PID page: the plant one of four ways (fn and zeta, its parts, a typed model, the identify page's
// result), the tuning, the op-amps; POST /api/pid?view=page as they change. The answer is design-pid's
// JSON with the closed-loop and loop-gain traces, the schematic and the build sheet without its pictures.
"use strict";
D.nav("/pid");
const form = document.getElementById("form");
const status = document.getElementById("status");
let seq = 0, last = null;
const identified = JSON.parse(sessionStorage.getItem("identify-result") || "null");

function plantKind() { return form.querySelector("input[name=plant]:checked").value; }

const SEED_TOPOLOGY = "sallen-key-lowpass";   // the seed's circuit: its parts by their own fields (R1 .. gain K)
let topologies = [];

// A plant as built on another registered section: one field per declared part (its designator, its role), the
// values typed as "REF=VALUE" items of the plant-part field the API takes (the address keeps them there).
function showSection() {
  const name = form.elements["plant-topology"].value, seed = name === SEED_TOPOLOGY;
  document.getElementById("seed-parts").hidden = !seed;
  document.getElementById("section-parts").hidden = seed;
  const box = document.getElementById("section-part-fields");
  const topo = topologies.find(t => t.name === name);
  if (seed || !topo) { box.replaceChildren(); return; }
  const typed = Object.fromEntries(String(form.elements["plant-part"].value || "").split(/\s+/).filter(Boolean)
                                   .map(x => x.split("=")).map(([k, ...v]) => [k, v.join("=")]));
  box.replaceChildren(...topo.parts.map(x => {
    const label = document.createElement("label"), input = document.createElement("input");
    label.title = D.t(x.role);
    input.dataset.ref = x.ref;
    input.value = typed[x.ref] || "";
    input.placeholder = x.kind === "R" ? "10k" : "10n";
    label.append(`${x.ref} `, input);
    return label;
  }));
}

// the section's fields as plant-part's items ("R1=10k"), in its declared order
function sectionParts() {
  return [...document.querySelectorAll("#section-part-fields input")].filter(i => i.value.trim())
    .map(i => `${i.dataset.ref}=${i.value.trim()}`);
}

function showPlantKind() {
  for (const d of form.querySelectorAll("[data-plant]")) d.hidden = d.dataset.plant !== plantKind();
}

// the targets are the optimiser's: with a rule chosen they are off (and not sent, which design-pid would refuse)
function showTargets() {
  const optimize = form.querySelector("select[name=tuning]").value === "optimize";
  for (const name of ["target-overshoot", "target-settling"]) form.querySelector(`[name=${name}]`).disabled = !optimize;
}

function request() {
  const o = D.options(form);
  delete o.plant;
  if (plantKind() === "parts") {
    // the seed's circuit by its own fields (as ever); another section by its declared parts
    if (o["plant-topology"] === SEED_TOPOLOGY) delete o["plant-topology"];
    else {
      const items = sectionParts();
      form.elements["plant-part"].value = items.join(" ");
      if (items.length) o["plant-part"] = items; else delete o["plant-part"];
    }
  }
  // the tolerance panel's fields hold several items apart ("R=1% C=5%"): the API takes them as a list
  for (const k of ["tol", "limit"]) if (o[k]) o[k] = o[k].split(/\s+/);
  if (plantKind() === "identify") {
    if (!identified) return null;
    o["plant-model"] = identified;   // identify's own --json, as design-pid --plant-model reads it
  }
  return o;
}

function show(answer) {
  const r = answer.result, p = answer.page;
  document.getElementById("title").textContent = p.title;
  const t = r.tuning || {};
  const cl = r.closed_loop || {};
  const a = cl.spice || cl.analytic || {};
  const m = cl.margins || {};
  // the peak sensitivity, for either plant kind: the page's part of the answer has it (the Sallen-Key plant's
  // result JSON leaves it out, so that design-pid's reference outputs keep their bytes)
  const sens = p.sensitivity || {};
  const failed = (r.checks || []).filter(c => !c.ok);
  document.getElementById("figures").replaceChildren(
    D.fig(D.t("method"), r.method || t.method || ""),
    D.fig("Kp", t.kp !== undefined ? D.num(t.kp, 4) : ""),
    D.fig("Ti", D.eng(t.ti_s, "s")), D.fig("Td", D.eng(t.td_s, "s")),
    D.fig(cl.spice ? D.t("overshoot (SPICE)") : D.t("overshoot (analytic)"), a.overshoot_pct !== undefined && a.overshoot_pct !== null ? D.localNum(`${(+a.overshoot_pct).toPrecision(3)} %`) : D.t("n/a")),
    D.fig(D.t("phase margin"), m.phase_margin_deg === undefined || m.phase_margin_deg === null ? D.t("n/a") : `${D.num(m.phase_margin_deg, 3)} deg`),
    D.fig(D.t("gain margin"), m.gain_margin_db === undefined || m.gain_margin_db === null ? D.t("n/a") : `${D.num(m.gain_margin_db, 3)} dB`),
    D.fig(D.t("crossover"), D.eng(m.crossover_hz, "Hz", 4)),
    D.fig(D.t("Ms (max sensitivity)"), D.num(sens.ms, 3)),
    D.fig(D.t("checks failed"), String(failed.length)));
  // the failing checks by their titles, first thing under the heading (the sheet below has their details)
  const f = document.getElementById("failed");
  f.replaceChildren();
  if (failed.length) {
    const line = document.createElement("p");
    line.className = "fail";
    line.textContent = D.t("Checks failed: {titles}", {titles: failed.map(D.checkTitle).join(", ")});
    f.append(line);
  }
  D.plot(document.getElementById("closed"), p.closed_loop, {xUnit: "s", yLabel: D.t("output (V)")});
  // the margins where they are read: the gain crossover (phase margin), the phase crossover (gain margin) and
  // the sensitivity peak (Ms), the same three for either plant kind
  const marks = [];
  if (isFinite(m.crossover_hz)) marks.push({x: m.crossover_hz, label: D.t("crossover: PM {pm} deg", {pm: D.num(m.phase_margin_deg, 3)})});
  if (isFinite(m.phase_crossover_hz)) marks.push({x: m.phase_crossover_hz, label: D.t("-180 deg: GM {gm} dB", {gm: D.num(m.gain_margin_db, 3)})});
  if (sens.ms_hz !== undefined && sens.ms_hz !== null && isFinite(sens.ms_hz)) marks.push({x: sens.ms_hz, label: D.t("max sensitivity: Ms {ms}", {ms: D.num(sens.ms, 3)})});
  D.plot(document.getElementById("lg-gain"), p.loop_gain.gain, {xUnit: "Hz", yLabel: D.t("gain (dB)"), height: 220, marks});
  D.plot(document.getElementById("lg-phase"), p.loop_gain.phase, {xUnit: "Hz", yLabel: D.t("phase (deg)"), height: 180, marks});
  D.schematic(document.getElementById("schematic"), p.schematic_svg, D.t("schematic of the loop: {title}", {title: p.title}));
  D.tolerance(r.monte_carlo, p.histograms);
  D.sheet(document.getElementById("sheet-html"), p.sheet_html, form);
}

async function design() {
  const opts = request();
  if (opts === null) {   // "identified" chosen with no model: what is shown is another plant's
    D.markStale(D.t("No identified model yet (drop a capture on the Identify page): what is shown below is of " +
                    "the plant chosen before, not of the current inputs."));
    return;
  }
  const mine = ++seq;
  D.markStale("pending");
  D.busy(true, status);
  const r = await D.api("/api/pid?view=page", opts, false, "form");
  if (r.aborted || mine !== seq) return;
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); D.answered("error"); return; }
  D.clearError(form);
  last = {opts, answer: r.data};
  // an identified model lives in this browser's session only: no link for it
  if (plantKind() !== "identify") D.remember({plant: plantKind(), ...opts});
  show(r.data);
  status.textContent = D.t("designed and simulated");
  D.answered("done");
}

async function file(kind) {
  if (!last || D.isStale()) return;
  D.busy(true, status);
  const r = await D.api(`/api/pid/${kind}`, last.opts, true);
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); return; }
  // the sheet in a new tab to print; a browser that blocks the tab gets it as a file
  if (kind === "sheet") { if (!window.open(URL.createObjectURL(r.blob), "_blank")) D.download(r.blob, "build-sheet.html"); }
  else D.download(r.blob, r.filename || "pid.zip");
}

(async function () {
  const c = await D.loadChoices();
  for (const s of form.querySelectorAll("select[data-choices]")) {
    const keepFirst = s.options.length ? [s.options[0].value] : [];
    D.fill(s, [...keepFirst, ...c[s.dataset.choices]], s.dataset.default || keepFirst[0]);
    if (keepFirst.length && s.options[0].value === "") s.options[0].textContent = D.t("default");
  }
  topologies = c.topologies;
  const menu = form.elements["plant-topology"];
  D.fill(menu, topologies.map(t => t.name), SEED_TOPOLOGY);
  for (const o of menu.options) o.textContent = D.t(topologies.find(t => t.name === o.value).title);
  D.fillFromQuery(form);
  D.onRestore = () => { showPlantKind(); showTargets(); showSection(); };
  if (identified) {
    const b = identified.best || {};
    document.getElementById("model-text").textContent =
      D.t("From {source}: {name} ({model}) {params}", {source: identified.capture ? identified.capture.source : D.t("the identify page"),
          name: b.name, model: b.model, params: Object.entries(b.params || {}).map(([k, v]) => D.param(k, v)).join(", ")});
  }
  showPlantKind();
  showTargets();
  showSection();
  // the plant's kind shows its fields before the form is read (a section's own, empty, when it changes)
  form.addEventListener("change", e => {
    if (e.target.name === "plant") showPlantKind();
    if (e.target.name === "tuning") showTargets();
    if (e.target.name === "plant-topology") { form.elements["plant-part"].value = ""; showSection(); }
  }, true);
  const live = D.liveForm(form, design, () => JSON.stringify(request()));
  document.getElementById("sheet").onclick = () => file("sheet");
  document.getElementById("bundle").onclick = () => file("bundle");
  live.now();   // (through the form: typing back to these inputs asks nothing)
})();
