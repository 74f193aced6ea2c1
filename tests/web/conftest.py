"""The session's designer-web server (:mod:`webserver`)."""

import pytest

from webserver import Server


@pytest.fixture(scope="session")
def server():
    s = Server()
    yield s
    err = s.stop()
    # a clean stop: no traceback, no warning from the server, its workers or their simulations
    assert "Traceback" not in err and "Warning" not in err, err
