"""designer-web's trust boundary: which requests it answers at all, and the
headers on every answer.

A page the student opens on another site can send a "simple" cross-site request
to the server (a POST of ``text/plain``, a form, no preflight), and a page at a
name that its owner re-points at 127.0.0.1 (DNS rebinding) can also read the
answers. So, as Jupyter and the local dev servers that care do (and as the
Fetch standard's CORS rules make sufficient):

- **Host**: a request is answered only when its ``Host`` header names the
  server: the address it serves and its port; for a loopback bind also
  ``localhost``, ``127.0.0.1`` and ``[::1]``; for a wildcard bind
  (``0.0.0.0``, ``::``) the machine's own names and any address of this machine;
  and the names given with ``--allow-origin``. Anything else is a 403.
- **Origin**: when present (a browser sends it on every POST) it must be the
  server's own (``http://`` and an accepted Host) or one given with
  ``--allow-origin``; ``null`` (a sandboxed frame, a file) and a foreign origin
  are a 403.
- **Content type**: the JSON endpoints take ``application/json`` only (415
  otherwise): a cross-site page cannot send it without a preflight, which this
  server never approves. The uploads (``/api/identify``, ``/api/check``) also
  take a multipart form or a raw body, types a cross-site ``<form>`` can send:
  those need the ``X-Designer`` header as well (the page sends it; a cross-site
  page cannot without a preflight), unless the body's type is one a browser
  only sends after a preflight (``text/csv``, ``application/octet-stream``...).
- **Headers** on every answer (pages, static files, the API, errors): a
  Content-Security-Policy with no outside source (scripts from this server
  only, no inline script; inline styles allowed, which run no code and with
  every fetch limited to this server exfiltrate nothing), ``frame-ancestors
  'none'`` and ``X-Frame-Options: DENY``, ``X-Content-Type-Options: nosniff``,
  ``Referrer-Policy: no-referrer``, ``Cross-Origin-Resource-Policy:
  same-origin``.

A pure ASGI middleware (not Starlette's ``BaseHTTPMiddleware``, which runs the
endpoint in another task and breaks streaming and the disconnect checks the
queue relies on).
"""

from __future__ import annotations

import ipaddress
import socket
from typing import NamedTuple
from urllib.parse import urlsplit

from starlette.responses import JSONResponse

from ..core.errors import DesignError

__all__ = ["CSP", "SECURITY_HEADERS", "JSON_PATHS", "PAGE_HEADER", "UPLOAD_PATHS", "Guard", "Trust", "error_response",
           "origin_of", "trust_for"]

#: the pages' Content-Security-Policy: nothing from outside this server, no inline script, no framing
CSP = ("default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data: blob:; "
       "connect-src 'self'; font-src 'self'; object-src 'none'; base-uri 'none'; form-action 'self'; "
       "frame-ancestors 'none'")
#: added to every answer
SECURITY_HEADERS = ((b"content-security-policy", CSP.encode()), (b"x-frame-options", b"DENY"),
                    (b"x-content-type-options", b"nosniff"), (b"referrer-policy", b"no-referrer"),
                    (b"cross-origin-resource-policy", b"same-origin"))
#: endpoints whose body is JSON, and only JSON
JSON_PATHS = frozenset({"/api/plant", "/api/plant/sheet", "/api/plant/bundle", "/api/analyze-plant", "/api/pid",
                        "/api/pid/sheet", "/api/pid/bundle", "/api/analyze-pid", "/api/filter", "/api/filter/sheet",
                        "/api/filter/bundle"})
#: endpoints that take an upload (a file as the body, a multipart form) or JSON
UPLOAD_PATHS = {"/api/identify": ("identify", "the file with its own type (text/csv, application/octet-stream)"),
                "/api/check": ("check-design", "JSON (Content-Type: application/json)")}
#: the header the page sends with every API call (a cross-site page cannot send it without a preflight)
PAGE_HEADER = b"x-designer"
#: the types a cross-site page may POST without asking first (the Fetch standard's CORS-safelisted ones)
_SIMPLE_TYPES = ("", "text/plain", "application/x-www-form-urlencoded", "multipart/form-data")
_LOOPBACK_NAMES = ("localhost", "127.0.0.1", "[::1]")


class Trust(NamedTuple):
    """What the server answers: its Host names and origins (see the module docstring)."""

    port: int                #: the port it serves
    hosts: frozenset         #: its own names as a ``Host`` gives them, lowercase (``127.0.0.1:8000``); its page's
                             #: origins are ``http://`` and one of them
    origins: frozenset       #: ``--allow-origin``'s origins (``https://lab.example.edu``)
    named: frozenset         #: their names as a ``Host`` gives them (``lab.example.edu``, ``lab.example.edu:8000``)
    any_local_address: bool  #: a wildcard bind: a Host that is an address of this machine is its own too


def origin_of(url: str) -> str:
    """``--allow-origin``'s URL as a browser writes an ``Origin``: ``scheme://host[:port]``, lowercase,
    the scheme's default port left out.

    Parameters
    ----------
    url : str
        A ``--allow-origin`` value.

    Returns
    -------
    str
        The origin.


    Raises
    ------
    DesignError
        Not an ``http://`` or ``https://`` URL with a host and nothing after it but ``/``.
    """
    text = str(url).strip()
    try:
        u = urlsplit(text)
        port = u.port
    except ValueError:
        u, port = None, None
    if u is None or u.scheme.lower() not in ("http", "https") or not u.hostname or u.path not in ("", "/") \
            or u.query or u.fragment or u.username or u.password:
        raise DesignError(f"--allow-origin {text[:80]!r}: give the page's origin as the browser shows it, "
                          "http://NAME:PORT or https://NAME (no path)")
    scheme = u.scheme.lower()
    host = u.hostname.lower()
    if ":" in host:
        host = f"[{host}]"
    default = 80 if scheme == "http" else 443
    return f"{scheme}://{host}" + (f":{port}" if port not in (None, default) else "")


def _with_port(host: str, port: int) -> set:
    """A Host header's forms for ``host`` on ``port`` (the port left out on 80, as browsers do)."""
    return {f"{host}:{port}"} | ({host} if port == 80 else set())


def trust_for(bind: str, port: int, allow_origins=()) -> Trust:
    """The :class:`Trust` of a server bound to ``bind``:``port``, with ``--allow-origin`` URLs.

    Parameters
    ----------
    bind : str
        The address the server listens on.
    port : int
        Its port.
    allow_origins : iterable of str, optional
        The ``--allow-origin`` URLs.

    Returns
    -------
    Trust
        Its port, its own Host names, the allowed origins and their Host names, and
        whether the bind is a wildcard.
    """
    origins = frozenset(origin_of(u) for u in allow_origins)
    hosts = set()
    try:
        ip = ipaddress.ip_address(bind)
    except ValueError:
        ip = None
    wildcard = ip is not None and ip.is_unspecified
    shown = f"[{bind}]" if ip is not None and ip.version == 6 else bind.lower()
    hosts |= _with_port(shown, port)
    if bind == "localhost" or (ip is not None and (ip.is_loopback or wildcard)):
        for name in _LOOPBACK_NAMES:
            hosts |= _with_port(name, port)
    if wildcard:
        for name in {socket.gethostname(), socket.getfqdn()}:
            if name:
                hosts |= _with_port(name.lower(), port)
    named = set()
    for origin in origins:
        u = urlsplit(origin)
        named.add(u.netloc)                                 # as the browser sends it (through a proxy too)
        name = f"[{u.hostname}]" if ":" in u.hostname else u.hostname
        named |= _with_port(name, port)                     # the same name at this server's own port
    return Trust(port, frozenset(hosts), origins, frozenset(named), wildcard)


class _LocalAddresses:
    """Whether an address is this machine's (it can be bound), remembered: a wildcard bind's Host check."""

    def __init__(self):
        self.known = {}

    def __call__(self, text: str) -> bool:
        if text in self.known:
            return self.known[text]
        try:
            ip = ipaddress.ip_address(text)
        except ValueError:
            return False
        try:
            with socket.socket(socket.AF_INET6 if ip.version == 6 else socket.AF_INET, socket.SOCK_DGRAM) as s:
                s.bind((str(ip), 0))
            local = True
        except OSError:
            local = False
        if len(self.known) < 1024:
            self.known[text] = local
        return local


def error_response(code: int, line: str, field: str | None = None, label: str | None = None) -> JSONResponse:
    """An error answer: the one line, its message (the line without the command's name) and the option it
    names (for the page), as every refusal of the server is written; a library refusal already in the page's
    words gives the ``field`` it names (``option`` is then ``--`` and the field) and that field's ``label``.

    Parameters
    ----------
    code : int
        The HTTP status.
    line : str
        The one-line error, as the command line writes it.
    field : str, optional
        The page's field the refusal names.
    label : str, optional
        That field's label.

    Returns
    -------
    JSONResponse
        ``error``, ``message`` and ``option`` (with ``field`` and ``label`` when given).
    """
    import re
    line = " ".join(str(line).split())
    message = re.sub(r"^[a-z-]+: error: ", "", line)
    if field is not None or label is not None:
        return JSONResponse({"error": line, "message": message, "option": None if field is None else "--" + field,
                             "field": field, "label": label}, status_code=code)
    found = re.search(r"--[a-z][a-z0-9-]*", message)
    return JSONResponse({"error": line, "message": message, "option": found.group(0) if found else None},
                        status_code=code)


class Guard:
    """The ASGI middleware around the application: refuses (403, 415) what the module docstring
    says, adds :data:`SECURITY_HEADERS` to every answer.

    Parameters
    ----------
    app : ASGI application
        The server's application.
    trust : Trust
        What it answers (:func:`trust_for`).
    """

    def __init__(self, app, trust: Trust):
        self.app = app
        self.trust = trust
        self.local = _LocalAddresses()

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def send_with_headers(message):
            if message["type"] == "http.response.start":
                present = {k.lower() for k, _ in message.get("headers", [])}
                message = dict(message)
                message["headers"] = list(message.get("headers", [])) + [
                    (k, v) for k, v in SECURITY_HEADERS if k not in present]
            await send(message)

        refusal = self.refusal(scope)
        if refusal is not None:
            await error_response(*refusal)(scope, receive, send_with_headers)
            return
        await self.app(scope, receive, send_with_headers)

    def host_ok(self, host: str, allowed_names: bool = True) -> bool:
        """Whether ``host`` (a Host header's value, or an origin's host and port) names this server
        (``allowed_names``: a name given with ``--allow-origin`` too)."""
        host = host.lower()
        if host in self.trust.hosts or (allowed_names and host in self.trust.named):
            return True
        if not self.trust.any_local_address:
            return False
        name, _, port = host.rpartition(":")
        if not name or (port != str(self.trust.port)):
            name, port = host, "80"
            if self.trust.port != 80:
                return False
        return self.local(name.strip("[]"))

    def refusal(self, scope) -> tuple | None:
        """(status, one line) when the request is refused, else None."""
        headers = {}
        for k, v in scope.get("headers", []):
            headers.setdefault(k.lower(), v.decode("latin-1"))
        host = headers.get(b"host")
        if host is None:
            return 403, "designer-web: error: a request without a Host header is refused"
        if not self.host_ok(host.strip()):
            return 403, (f"designer-web: error: Host {host[:80]!r} is not this server's name: refused (a page "
                         "at another name must be allowed with designer-web --allow-origin)")
        origin = headers.get(b"origin")
        if origin is not None:
            own = origin.lower().rstrip("/")
            ok = own in self.trust.origins or (own.startswith("http://") and
                                               self.host_ok(own[len("http://"):], allowed_names=False))
            if not ok:
                return 403, (f"designer-web: error: Origin {origin[:80]!r} is not this server's page: refused "
                             "(a lab's own name is allowed with designer-web --allow-origin)")
        if scope.get("method") != "POST":
            return None
        path = scope.get("path", "")
        media = headers.get(b"content-type", "").split(";")[0].strip().lower()
        if path in JSON_PATHS and media != "application/json":
            return 415, (f"designer-web: error: {path} takes a JSON body with Content-Type: application/json, "
                         f"got {media or 'none'!r}")
        if path in UPLOAD_PATHS and media in _SIMPLE_TYPES and PAGE_HEADER not in headers:
            prog, other = UPLOAD_PATHS[path]
            return 415, (f"{prog}: error: {path} takes a body of Content-Type {media or 'none'!r} only with the "
                         f"header X-Designer: 1 (the page sends it); or send {other}")
        return None
