// The filter page: the form's fields go to POST /api/filter?view=page as they change (debounced), the order and
// cut-off or a mask that picks the order; the answer is design-filter's JSON with the Bode plot's data (the mask
// drawn), the stages with their op-amp checks, the schematic (SVG), the BOM and the build sheet's content.
"use strict";
D.nav("/filter");
const form = document.getElementById("form");
const status = document.getElementById("status");
const entry = document.getElementById("entry");

// Only the fields of the entry, type and family chosen are sent (a hidden field is left out by D.options).
function showFields() {
  const type = form.elements["type"].value, family = form.elements["family"].value;
  for (const el of form.querySelectorAll("[data-entry]")) el.hidden = el.dataset.entry !== entry.value;
  for (const el of form.querySelectorAll("[data-type]")) el.hidden = !el.dataset.type.split(" ").includes(type);
  for (const el of form.querySelectorAll("[data-family]")) el.hidden = el.dataset.family !== family;
}
// A shared link says which entry it used: a mask's fields, or the order's.
function entryFromQuery() {
  entry.value = new URLSearchParams(location.search).has("passband") ? "mask" : "order";
  showFields();
}
D.onRestore = entryFromQuery;

const hz = v => D.eng(v, "Hz", 4);
const hzs = v => Array.isArray(v) ? v.map(hz).join(D.t(" and ")) : hz(v);
const db = v => `${D.num(v, 3)} dB`;

function show(answer) {
  const r = answer.result, p = answer.page, f = r.figures, s = r.spec;
  document.getElementById("title").textContent = p.title;
  const figs = [D.fig(D.t("order"), String(s.order)), D.fig(D.t("stages"), String(r.stages.length)),
                D.fig(D.t("-3 dB frequency (target)"), hzs(f.f3_target_hz)),
                D.fig(D.t("-3 dB frequency as built ({amp} model)", {amp: r.opamp.name}), hzs(f.f3_hz)),
                D.fig(D.t("largest passband deviation from the ideal"), db(f.passband_deviation_db)),
                D.fig(D.t("E-series error, joint choice"), db(f.error_joint_db)),
                D.fig(D.t("E-series error, each stage rounded"), db(f.error_per_stage_db))];
  if (s.mask) {
    figs.push(D.fig(D.t("mask: passband margin"), db(f.mask_passband_margin_db)),
              D.fig(D.t("mask: stopband margin"), db(f.mask_stopband_margin_db)));
  }
  figs.push(D.fig(D.t("SPICE agrees with the model"), !r.spice ? D.t("not simulated")
                  : `${r.spice.passed ? D.t("yes") : D.t("NO")} (${db(r.spice.max_deviation_passband_db)})`));
  document.getElementById("figures").replaceChildren(...figs);
  document.getElementById("stages").replaceChildren(D.table(
    [D.t("stage"), D.t("section"), D.t("fn"), D.t("Q"), D.t("gain"), D.t("peak gain"), D.t("parts"),
     D.t("output peak (swing)"), D.t("GBW needed (has)"), D.t("slew needed (has)"), D.t("check")],
    p.stages.map(st => {
      const ok = document.createElement("span");
      ok.className = st.ok ? "ok" : "fail";
      ok.textContent = st.ok ? D.t("ok") : D.t("FAILED");
      return [st.stage, st.topology, hz(st.fn_hz), st.q === null ? D.t("first order") : D.num(st.q, 4),
              D.num(st.gain, 4), `${D.num(st.peak_gain_db, 3)} dB`, st.parts,
              `${D.eng(st.out_peak_v, "V", 3)} (${D.eng(st.swing_v, "V", 3)})`,
              `${D.eng(st.gbw_needed_hz, "Hz", 3)} (${D.eng(st.gbw_hz, "Hz", 3)})`,
              `${D.eng(st.slew_needed_v_per_s, "V/s", 3)} (${D.eng(st.slew_v_per_s, "V/s", 3)})`, ok];
    })));
  // --alternatives N: the joint search's best part sets, as the sheet lists them (none asked: no section)
  document.getElementById("alternatives-section").hidden = !p.alternatives.length;
  const limited = p.alternatives.some(a => a.limits);   // a mask or a delay target: met or broken
  document.getElementById("alternatives").replaceChildren(D.table(
    [D.t("rank"), D.t("worst deviation from the ideal"), ...(limited ? [D.t("limits")] : []), D.t("parts")],
    p.alternatives.map(a => [a.rank, db(a.error_db), ...(limited ? [a.limits] : []), a.parts])));
  D.schematic(document.getElementById("schematic"), p.schematic_svg,
              D.t("schematic: {parts}", {parts: p.bom.rows.map(x => `${x[0]} ${x[1]}`).join(", ")}));
  document.getElementById("bomtable").replaceChildren(D.bomTable(p));
  D.tolerance(r.monte_carlo, p.histograms);
  const t = r.monte_carlo && r.monte_carlo.tighten;
  document.getElementById("tighten-stage").textContent = t && t.stage_yield > t.yield_now
    ? D.t("Or buy every part of stage {stage} at half its tolerance: the yield is {y}.", {stage: t.stage, y: D.pct(t.stage_yield)})
    : "";
  D.sheet(document.getElementById("sheet-html"), p.sheet_html, form);
  D.plot(document.getElementById("bode-gain"), p.bode.gain, {xUnit: "Hz", yLabel: D.t("gain (dB)"), height: 260});
  D.plot(document.getElementById("bode-phase"), p.bode.phase, {xUnit: "Hz", yLabel: D.t("phase (deg)"), height: 200});
}

const page = D.designPage(form, status, "/api/filter", show, r => r.result.spice ? D.t("designed and proven in SPICE") : D.t("designed (not simulated)"));

(async function () {
  const c = await D.loadChoices();
  for (const s of form.querySelectorAll("select[data-choices]")) D.fill(s, c[s.dataset.choices], s.dataset.default);
  D.fillFromQuery(form);
  entryFromQuery();
  // the entry, type or family chosen shows its fields (the change then asks, as any menu does)
  form.addEventListener("change", e => { if (e.target === entry || ["type", "family"].includes(e.target.name)) showFields(); },
                        true);
  const live = D.liveForm(form, page.design, () => JSON.stringify(D.options(form)));
  document.getElementById("sheet").onclick = () => page.file("sheet");
  document.getElementById("bundle").onclick = () => page.file("bundle");
  document.getElementById("bom").onclick = () => page.file("bom");
  live.now();   // (through the form: typing back to these inputs asks nothing)
})();
