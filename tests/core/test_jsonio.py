"""read_result: a result file a command wrote, read back; anything else (here: a key given twice in one
object, which json.loads would settle silently by keeping the last) refused in one line."""

import json

import pytest

from designer.core.errors import DesignError
from designer.core.jsonio import read_result


@pytest.mark.parametrize("text, key", [
    ('{"best": null, "best": {"name": "x"}}', "best"),
    ('{"methods": [{"name": "a", "valid": true, "valid": false}]}', "valid"),
    ('{"built": {"fn_hz": 1, "zeta": 0.2, "fn_hz": 2}}', "fn_hz"),
])
def test_a_key_twice_in_one_object_is_refused_naming_it(tmp_path, text, key):
    path = tmp_path / "r.json"
    path.write_text(text)
    json.loads(text)   # json itself takes it, keeping the last
    with pytest.raises(DesignError) as exc:
        read_result(path, "--plant-model", what="an identify --json output")
    msg = str(exc.value)
    assert msg.startswith(f"--plant-model: {path} has the key {key!r} twice in one object") and "\n" not in msg
    assert "expected an identify --json output" in msg


def test_the_same_key_in_different_objects_is_fine(tmp_path):
    data = {"a": {"name": 1}, "b": [{"name": 2}, {"name": 3}], "name": 4}
    path = tmp_path / "r.json"
    path.write_text(json.dumps(data))
    assert read_result(path, "--x", what="anything") == data
