// The check page: a spec (typed, pasted or dropped) and the decks it names go to POST /api/check as JSON;
// check-design runs them with its trust boundary unchanged (decks inside the request's folder, no
// .control blocks). The answer: each spec's result.json, the JUnit XML and the Markdown summary.
"use strict";
D.nav("/check");
const form = document.getElementById("form");
const status = document.getElementById("status");
// every file chosen or dropped, by its path in the folder chosen (a folder's files keep their relative paths:
// specs/decks/rc_ladder.cir), and the specs among them (run all, as check-design specs/*.yaml does)
let files = {}, specs = [];
let specName = "spec.yaml", last = null;

async function addFiles(list) {
  const added = [];
  for (const f of list) {
    const path = f.webkitRelativePath || f.name;
    if (/\.(png|jpe?g|gif|pdf|zip|svg)$/i.test(path)) continue;   // pictures and bundles: no spec names them
    files[path] = await f.text();
    added.push(path);
  }
  const yaml = added.filter(p => /\.ya?ml$/i.test(p));
  // one spec alone: shown in the box to edit; several (a folder): each run as it is
  if (yaml.length === 1 && added.length === 1 && !specs.length) {
    document.getElementById("spec").value = files[yaml[0]]; specName = yaml[0]; delete files[yaml[0]];
  } else for (const p of yaml) if (!specs.includes(p)) specs.push(p);
  showFiles();
}
function showFiles() {
  const names = Object.keys(files);
  document.getElementById("decks").textContent = D.t("Files: {names}", {names: names.join(", ") || D.t("none")}) +
    (specs.length ? D.t(" (specs run: {specs})", {specs: specs.join(", ")}) : "");
}
document.getElementById("clear").onclick = () => { files = {}; specs = []; showFiles(); };

// a case's status as the page's language says it
const STATUS = {pass: D.N_("pass"), fail: D.N_("fail"), skipped: D.N_("skipped"), error: D.N_("error")};

function show(answer) {
  const v = document.getElementById("verdict");
  v.innerHTML = "";
  for (const line of answer.lines) { const p = document.createElement("p"); p.textContent = line; v.append(p); }
  const rows = [];
  for (const s of answer.specs) {
    for (const corner of s.corners || []) {
      for (const c of corner.cases || []) {
        const st = document.createElement("span");
        st.className = c.status === "pass" ? "ok" : c.status === "skipped" ? "" : "fail";
        st.textContent = D.t(STATUS[c.status] || c.status);
        rows.push([s.spec.name, c.corner || corner.corner || "-", c.id, st, c.message || ""]);
      }
    }
  }
  const t = D.table([D.t("spec"), D.t("corner"), D.t("check"), D.t("status"), D.t("detail")], rows);
  t.id = "cases-table";
  document.getElementById("cases").replaceChildren(t);
  document.getElementById("summary").textContent = answer.summary || "";
  const golden = document.getElementById("golden");
  const recorded = Object.entries(answer.golden || {});
  golden.replaceChildren(...(recorded.length ? recorded.map(([path, text]) => {
    const b = document.createElement("button");
    b.type = "button";
    b.textContent = D.t("{path} (download)", {path});
    b.dataset.current = "";
    b.className = "golden-file";
    b.onclick = () => { if (!D.isStale()) D.download(new Blob([text], {type: "text/csv"}), path.split("/").pop()); };
    return b;
  }) : [Object.assign(document.createElement("p"), {textContent: D.t("none recorded in this run")})]));
}

// a refused run leaves no result to read: the previous run's table, summary and junit.xml are cleared
D.onStale = function (why) {
  if (why !== "refused") return;
  last = null;
  for (const id of ["verdict", "cases", "summary", "golden"]) document.getElementById(id).replaceChildren();
};

async function run() {
  D.markStale("pending");
  D.busy(true, status);
  const body = specs.length ? {specs, files, options: D.options(form)} :
    {spec: document.getElementById("spec").value, spec_name: specName, files, options: D.options(form)};
  const r = await D.api("/api/check", body);
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); D.answered("error"); return; }
  D.clearError(form);
  last = r.data;
  show(r.data);
  status.textContent = r.data.status === 0 ? D.t("every check passed") : D.t("a check failed");
  D.answered("done");
  document.getElementById("junit").disabled = !r.data.junit;
}

D.dropZone(document.getElementById("drop"), document.getElementById("files"), addFiles);
document.getElementById("folder").addEventListener("change", e => { if (e.target.files.length) addFiles(e.target.files); });
document.getElementById("run").onclick = run;
document.getElementById("junit").onclick = () => last && D.download(new Blob([last.junit], {type: "application/xml"}), "junit.xml");
