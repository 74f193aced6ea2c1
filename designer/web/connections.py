"""How ``designer-web`` holds its connections and stops: deadlines on what a
client sends, and a stop that answers every request at once.

- **Header and body deadlines** (:class:`GuardedH11`). uvicorn (0.55, with h11)
  closes a connection that stays idle after an answer (``timeout_keep_alive``),
  but has no deadline on a request's headers or body: a client that opens a
  socket and sends half a header, or a body a byte at a time, holds the
  connection for ever (a "slowloris"; 500 such sockets were held 25 s and more,
  none closed). Here a request's headers must arrive within
  :data:`HEADER_TIMEOUT_S` seconds of the connection (or of the previous
  answer), and its body at :data:`MIN_BODY_RATE` bytes a second at least, after
  :data:`BODY_GRACE_S` seconds of grace; a connection that falls behind is
  closed. The clock of a body stops while the page's code is not reading it
  (uvicorn then stops reading the socket: the client is not the slow one).
  Apache's ``mod_reqtimeout`` sets the same two limits (its defaults: headers
  20-40 s, body 20 s then 500 bytes/s).
- **Stopping** (:class:`StoppingServer`). On SIGTERM or SIGINT uvicorn stops
  accepting, then waits for every request under way to be answered: a run of
  minutes held the stop that long (58 s measured) and a queued request got no
  answer. Here the signal first stops the worker pool
  (:meth:`designer.web.pool.Pool.stop_now`): every run is killed with its
  ngspice and every request waiting, queued or running, is answered 503 at
  once; uvicorn's graceful wait is bounded by :data:`STOP_GRACE_S`.
"""

from __future__ import annotations

import h11
import uvicorn
from uvicorn.protocols.http.h11_impl import H11Protocol

__all__ = ["BODY_GRACE_S", "GuardedH11", "HEADER_TIMEOUT_S", "MIN_BODY_RATE", "STOP_GRACE_S", "StoppingServer"]

#: seconds a request's headers may take to arrive, from the connection (or the previous answer)
HEADER_TIMEOUT_S = 5.0
#: seconds of grace for a body before its rate is held to :data:`MIN_BODY_RATE`
BODY_GRACE_S = 5.0
#: bytes a second a body must arrive at, at least, once the grace is spent (a 256 MiB capture: 2 h)
MIN_BODY_RATE = 32 * 1024
#: seconds between two looks at a connection's progress
_TICK_S = 0.25
#: seconds uvicorn waits for answers still being sent when the server stops
STOP_GRACE_S = 3.0


class GuardedH11(H11Protocol):
    """uvicorn's HTTP/1.1 protocol with header and body deadlines (see the module's text);
    ``uvicorn.Config(http=GuardedH11)``."""

    def connection_made(self, transport) -> None:
        super().connection_made(transport)
        self._restart()
        self._watch = self.loop.call_later(_TICK_S, self._check)

    def _restart(self) -> None:
        """A new phase of the connection (waiting for headers, receiving a body...): its own clock."""
        self._since, self._got, self._phase = self.loop.time(), 0, self.conn.their_state

    def data_received(self, data: bytes) -> None:
        super().data_received(data)
        if self.conn.their_state is not self._phase:
            self._restart()
        elif self._phase is h11.SEND_BODY:
            self._got += len(data)

    def on_response_complete(self) -> None:
        super().on_response_complete()
        self._restart()   # the next request's headers are timed from this answer

    def connection_lost(self, exc) -> None:
        self._watch.cancel()
        super().connection_lost(exc)

    def _check(self) -> None:
        if self.transport.is_closing():
            return
        state = self.conn.their_state
        if state is not self._phase:
            self._restart()
        waited = self.loop.time() - self._since
        late = False
        if state is h11.IDLE:
            late = waited > HEADER_TIMEOUT_S
        elif state is h11.SEND_BODY:
            if self.flow.read_paused:   # the application is not reading the body: not the client's delay
                self._restart()
            else:
                late = waited > BODY_GRACE_S + self._got / MIN_BODY_RATE
        if late:
            self.transport.close()   # connection_lost follows: a request under way sees its client gone
            return
        self._watch = self.loop.call_later(_TICK_S, self._check)


class StoppingServer(uvicorn.Server):
    """uvicorn's server whose stop signal first stops ``pool`` (:meth:`.pool.Pool.stop_now`)."""

    def __init__(self, config: uvicorn.Config, pool):
        super().__init__(config)
        self.pool = pool

    def handle_exit(self, sig, frame) -> None:
        if not self.should_exit:
            self.pool.stop_now()
        super().handle_exit(sig, frame)

