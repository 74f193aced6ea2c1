// The check page: a spec (typed, pasted or dropped) and the decks it names go to POST /api/check as JSON;
// check-design runs them with its trust boundary unchanged (decks inside the request's folder, no
// .control blocks). The answer: each spec's result.json, the JUnit XML and the Markdown summary.
"use strict";
D.nav("/check");
const form = document.getElementById("form");
const status = document.getElementById("status");
const decks = {};
let specName = "spec.yaml", last = null;

async function addFiles(files) {
  for (const f of files) {
    const text = await f.text();
    if (/\.ya?ml$/i.test(f.name)) { document.getElementById("spec").value = text; specName = f.name; }
    else decks[f.name] = text;
  }
  document.getElementById("decks").textContent = "Decks: " + (Object.keys(decks).join(", ") || "none");
}

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
        st.textContent = c.status;
        rows.push([s.spec.name, c.corner || corner.corner || "-", c.id, st, c.message || ""]);
      }
    }
  }
  const t = D.table(["spec", "corner", "check", "status", "detail"], rows);
  t.id = "cases-table";
  document.getElementById("cases").replaceChildren(t);
  document.getElementById("summary").textContent = answer.summary || "";
}

// a refused run leaves no result to read: the previous run's table, summary and junit.xml are cleared
D.onStale = function (why) {
  if (why !== "refused") return;
  last = null;
  for (const id of ["verdict", "cases", "summary"]) document.getElementById(id).replaceChildren();
};

async function run() {
  D.markStale("pending");
  D.busy(true, status);
  const body = {spec: document.getElementById("spec").value, spec_name: specName, files: decks,
                options: D.options(form)};
  const r = await D.api("/api/check", body);
  D.busy(false, status);
  if (!r.ok) { D.showError(form, r.data); D.answered("error"); return; }
  D.clearError(form);
  last = r.data;
  show(r.data);
  status.textContent = r.data.status === 0 ? "every check passed" : "a check failed";
  D.answered("done");
  document.getElementById("junit").disabled = !r.data.junit;
}

D.dropZone(document.getElementById("drop"), document.getElementById("files"), addFiles);
document.getElementById("run").onclick = run;
document.getElementById("junit").onclick = () => last && D.download(new Blob([last.junit], {type: "application/xml"}), "junit.xml");
