"""examples/ci: the GitHub Actions workflow and the GitLab CI job are valid YAML
that install ngspice with apt, run check-design with the ngspice-cli backend,
publish the JUnit file and keep --out as an artifact; the README example spec loads."""

import re

import yaml
from helpers import ROOT

from designer.check.spec import load_spec

CI = ROOT / "examples" / "ci"


def _commands(node) -> str:
    return yaml.safe_dump(node)


def test_github_workflow():
    wf = yaml.safe_load((CI / "github-actions.yml").read_text())
    steps = wf["jobs"]["check-design"]["steps"]
    text = _commands(steps)
    assert "apt-get install -y -qq ngspice" in text
    run = next(s["run"] for s in steps if s.get("name") == "check-design")
    assert "--simulator ngspice-cli" in run and "--junit check-design.xml" in run and "--out check-design-out" in run
    assert "$GITHUB_STEP_SUMMARY" in run
    report = next(s for s in steps if s.get("name") == "JUnit report")
    assert report["if"] == "always()" and report["with"]["report_paths"] == "check-design.xml"
    upload = next(s for s in steps if s.get("name") == "results and build sheets")
    assert "check-design-out/" in upload["with"]["path"]


def test_gitlab_job():
    job = yaml.safe_load((CI / "gitlab-ci.yml").read_text())["spice-checks"]
    assert any("apt-get install -y -qq ngspice" in c for c in job["before_script"])
    assert any("--simulator ngspice-cli" in c and "--junit check-design.xml" in c for c in job["script"])
    assert job["artifacts"]["reports"]["junit"] == "check-design.xml"
    assert "check-design-out/" in job["artifacts"]["paths"] and job["artifacts"]["when"] == "always"


def test_the_readme_example_spec_loads(tmp_path):
    readme = (ROOT / "README.md").read_text()
    example = re.search(r"```yaml\n(# specs/lab3-plant.yaml\n.*?)```", readme, re.S).group(1)
    path = tmp_path / "lab3-plant.yaml"
    path.write_text(example)
    spec = load_spec(path, update_golden=True)   # its golden files are not recorded here
    assert spec.name == "lab3-plant" and spec.corners == ("LM741", "TL072") and spec.analyze
    assert spec.tolerance == ("fn_hz",)
