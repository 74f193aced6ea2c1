"""The web page's server: the pages (plain HTML and JavaScript, no build
step, every file served from this package: the lab may be offline) and the
JSON API under them.

``POST /api/plant``, ``/api/analyze-plant``, ``/api/filter``, ``/api/pid``, ``/api/analyze-pid``,
``/api/identify``, ``/api/check`` take the page's fields by the commands' option names (:mod:`.forms`), call
the library with them in a worker (:data:`.jobs.LIBRARY`: no command line built, no console script run) and
answer what the command's ``--json`` prints; ``?view=page`` adds what the page draws
(``{"result": ..., "page": ...}``). ``/api/plant/sheet`` and ``/bundle`` (and
the PID's) answer the printable build sheet and the design's files as a zip.
Bad input is a 400 whose ``error`` is the command's one line (a body that is
not UTF-8 JSON, nested too deeply, or a value of the wrong type: one line too);
an upload over the command's file limits a 413; a run past its deadline a 504.
Every command runs in the worker pool (:mod:`.pool`), each request in its own
private folder, removed when it is answered. Which requests are answered at all
(Host, Origin, content type) and the headers on every answer: :mod:`.guard`.

Starlette (routing, requests, responses) on uvicorn: see the README for why.
"""

from __future__ import annotations

import asyncio
import json
import logging
import os
import re
import shutil
import tempfile
from contextlib import asynccontextmanager
from pathlib import Path

from starlette.applications import Starlette
from starlette.requests import ClientDisconnect, Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from ..core.errors import DesignError
from ..core.fileio import MAX_CAPTURE_BYTES, check_plain_name
from . import pool as pool_module
from . import request as req
from .guard import Guard, Trust, error_response

__all__ = ["DISCONNECT_POLL_S", "MAX_DEPTH", "PAGES", "STATIC", "TooLarge", "create_app"]

__all__ = []

STATIC = Path(__file__).parent / "static"
MEDIA = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
         ".css": "text/css; charset=utf-8", ".txt": "text/plain; charset=utf-8", ".svg": "image/svg+xml",
         ".png": "image/png", "": "text/plain; charset=utf-8"}
#: the pages, by path
PAGES = {"/": "plant.html", "/plant": "plant.html", "/pid": "pid.html", "/identify": "identify.html",
         "/check": "check.html", "/filter": "filter.html"}
#: the commands' refusals of a file over their size limits (designer.core.fileio): answered 413
_TOO_LARGE = re.compile(r"the most this command reads|; at most [0-9.]+ [KMG]?i?B is read")
#: how often a waiting request looks whether its client is still there (a page typing on closes it): a
#: superseded run is stopped within this
DISCONNECT_POLL_S = 0.03
#: multipart framing around an upload (boundaries, part headers) allowed over the file's own limit
FRAMING_BYTES = 64 * 1024


def _check_limit() -> int:
    """check-design's inputs: a spec and the decks it includes (their own limits)."""
    from ..check.yamldoc import MAX_SPEC_BYTES
    from ..spice.trust import MAX_TOTAL_BYTES
    return MAX_SPEC_BYTES + MAX_TOTAL_BYTES + FRAMING_BYTES


class TooLarge(Exception):
    """A request body over its limit: answered 413."""


def create_app(pool, trust: Trust):
    """The application, its commands run by ``pool`` (a :class:`.pool.Pool`), answering the requests
    ``trust`` (:func:`.guard.trust_for`) lets in: an ASGI application."""
    # python-multipart logs a malformed form before it raises: the raise is the client's 400, the log line
    # would be noise on the server's stderr for every broken upload
    quiet = logging.getLogger("python_multipart")
    quiet.addHandler(logging.NullHandler())
    quiet.propagate = False
    static = {p.relative_to(STATIC).as_posix(): (p.read_bytes(), MEDIA.get(p.suffix, MEDIA[""]))
              for p in STATIC.rglob("*") if p.is_file()}

    @asynccontextmanager
    async def lifespan(app):
        pool.attach()
        try:
            yield
        finally:
            pool.close()

    def page(name):
        body, media = static[name]

        async def endpoint(request):
            return Response(body, media_type=media)
        return endpoint

    async def static_file(request):
        found = static.get(request.path_params["path"])
        if found is None:
            return JSONResponse({"error": "not found"}, status_code=404)
        return Response(found[0], media_type=found[1], headers={"Cache-Control": "no-cache"})

    async def health(request):
        return JSONResponse({"ok": True, "jobs": pool.jobs, "timeout_s": pool.timeout, "dropped": pool.dropped,
                             "ran": pool.ran, "superseded": pool.superseded})

    choices = _choices()

    async def choices_endpoint(request):
        return JSONResponse(choices)

    async def catalogue_endpoint(request):
        # the page's words in a language of the list (never a path: the code picks the catalogue's file);
        # none asked: the browser's Accept-Language
        from ..core import i18n
        lang = request.query_params.get("lang") or i18n.negotiate(request.headers.get("accept-language"))
        try:
            return JSONResponse(i18n.page_catalogue(lang), headers={"Cache-Control": "no-cache"})
        except DesignError as exc:
            return _error(400, f"designer-web: error: {exc}")

    async def run(request, prog: str, want: str, tmp: str, upload_name: str | None = None, fields: dict | None = None,
                  capture: str | None = None):
        # the task goes to the pool as its file's name: a message of a hundred bytes, so that the pipe to the
        # pool never fills while the pool is sending a long answer the other way (each would wait on the other)
        task_file = os.path.join(tmp, "task.json")
        # the library's task: the request's fields (their lang among them), never a command line
        task = {"prog": prog, "want": want, "tmp": tmp, "fields": fields}
        if capture is not None:   # an identify request's upload
            task["capture"] = capture
        with open(task_file, "w", encoding="utf-8") as fh:
            json.dump(task, fh)
        try:
            rid, answer = pool.start({"task_file": task_file})
        except pool_module.Busy as exc:
            return _error(503, f"{prog}: error: {exc}")
        # a page typing ahead drops its older requests: one whose client has gone leaves the queue
        while not answer.done():
            await asyncio.wait({answer}, timeout=DISCONNECT_POLL_S)
            if not answer.done() and await request.is_disconnected():
                pool.cancel(rid)
                await answer   # dropped from the queue at once, or its run finished: the folder is free
                return Response(status_code=204)
        kind, value = answer.result()
        if kind == "timeout":
            return _error(504, f"{prog}: error: simulator error: {value}")
        if kind != "ok":
            return _error(500 if kind == "crash" else 503 if kind == "stopped" else 502, f"{prog}: error: {value}")
        status = value["status"]
        if value["error"] is not None:
            line = _hide(value["error"], tmp, upload_name)
            code = 400 if status == 2 else 502 if status == 3 else 503
            if status == 2 and _TOO_LARGE.search(line):
                code = 413
            if "field" in value:   # the library's refusal in the page's words: the field it names
                return error_response(code, line, value["field"], value["label"])
            return _error(code, line)
        if want in ("sheet", "bundle"):
            return Response(value["body"], media_type=value["media"],
                            headers={"Content-Disposition": f'attachment; filename="{value["filename"]}"'})
        if want == "page":
            answer = {"result": value["json"], "page": value.get("page"), "status": status}
        elif prog == "check-design":
            answer = {"status": status, **value["json"], "junit": value["junit"], "summary": value["summary"],
                      "golden": value["golden"], "lines": value["lines"], "messages": value["messages"]}
        else:
            answer = value["json"]
        # the request's private folder is nobody's business: the upload by its own name
        return Response(_hide(json.dumps(answer), tmp, upload_name), media_type="application/json")

    def designing(prog: str, want: str | None = None):
        async def endpoint(request: Request):
            how = want or _view(request)
            with _private_folder() as tmp:
                try:
                    options = req.parse_json(await _body(request, req.MAX_JSON_BYTES))
                except TooLarge:
                    return _error(413, f"{prog}: error: the request is larger than "
                                       f"{req.MAX_JSON_BYTES // (1024 * 1024)} MiB")
                except DesignError as exc:
                    return _error(400, f"{prog}: error: {exc}")
                # the library called with the request's fields: no command line
                return await run(request, prog, how, tmp, fields=options)
        return endpoint

    async def identify(request: Request):
        prog = "identify"
        with _private_folder() as tmp:
            try:
                path, name, options = await _upload(request, tmp, MAX_CAPTURE_BYTES + FRAMING_BYTES, "capture")
            except TooLarge:
                return _error(413, f"{prog}: error: the capture is larger than "
                                   f"{MAX_CAPTURE_BYTES // (1024 * 1024)} MiB, the most identify reads; "
                                   "cut or decimate it")
            except DesignError as exc:
                return _error(400, f"{prog}: error: {exc}")
            # the library called with the request's fields and the capture: no command line
            return await run(request, prog, _view(request), tmp, name, fields=options, capture=path)

    async def check(request: Request):
        prog = "check-design"
        with _private_folder() as tmp:
            try:
                specs, options = await _check_inputs(request, tmp, _check_limit())
            except TooLarge:
                return _error(413, f"{prog}: error: the spec and its decks are larger than check-design reads")
            except DesignError as exc:
                return _error(400, f"{prog}: error: {exc}")
            # the library with the specs' paths inside the request's folder (its root: nothing outside it) and
            # the page's options; golden files recorded there are answered for download, never kept
            return await run(request, prog, "check", tmp, fields={"specs": specs, "options": options})

    routes = [Route(path, page(name)) for path, name in PAGES.items()]
    async def no_icon(request):
        return Response(status_code=204)

    routes += [Route("/static/{path:path}", static_file), Route("/api/health", health),
               Route("/favicon.ico", no_icon),
               Route("/api/choices", choices_endpoint),
               Route("/api/catalogue", catalogue_endpoint),
               Route("/api/plant", designing("design-plant"), methods=["POST"]),
               Route("/api/plant/sheet", designing("design-plant", "sheet"), methods=["POST"]),
               Route("/api/plant/bundle", designing("design-plant", "bundle"), methods=["POST"]),
               Route("/api/analyze-plant", designing("analyze-plant"), methods=["POST"]),
               Route("/api/filter", designing("design-filter"), methods=["POST"]),
               Route("/api/filter/sheet", designing("design-filter", "sheet"), methods=["POST"]),
               Route("/api/filter/bundle", designing("design-filter", "bundle"), methods=["POST"]),
               Route("/api/pid", designing("design-pid"), methods=["POST"]),
               Route("/api/pid/sheet", designing("design-pid", "sheet"), methods=["POST"]),
               Route("/api/pid/bundle", designing("design-pid", "bundle"), methods=["POST"]),
               Route("/api/analyze-pid", designing("analyze-pid"), methods=["POST"]),
               Route("/api/identify", identify, methods=["POST"]),
               Route("/api/check", check, methods=["POST"])]
    async def client_left(request, exc):
        # the client went away in the middle of its body (or its body deadline, connections.GuardedH11, closed
        # it): nobody reads an answer, and it is no error of ours (uvicorn would log a traceback)
        return Response(status_code=400)

    app = Starlette(routes=routes, lifespan=lifespan, exception_handlers={ClientDisconnect: client_left})
    return Guard(app, trust)


def _choices() -> dict:
    """What the forms offer in their lists: the op-amp catalogue, the E-series, the tuning rules, the filters'
    responses, families and stage topologies, and the registered sections (each with its declared parts)."""
    from ..cli.identify import FORMATS
    from ..core import opamps
    from ..core.eseries import SERIES
    from ..filters import registry
    from ..filters.prototype import FAMILIES, RESPONSE_TYPES
    from ..filters.spec import TOPOLOGY_CHOICES
    return {"opamps": opamps.names(), "series": list(SERIES), "formats": list(FORMATS),
            "tunings": ["zn", "cohen-coon", "chr0", "chr20", "amigo", "simc", "imc", "optimize"],
            "packages": ["single", "dual", "quad"], "filter_types": list(RESPONSE_TYPES),
            "families": list(FAMILIES), "filter_topologies": list(TOPOLOGY_CHOICES),
            "topologies": [{"name": n, "title": registry.get(n).title, "kind": registry.get(n).kind, "order": registry.get(n).order,
                            "parts": [{"ref": p.ref, "kind": p.kind, "role": p.role}
                                      for p in registry.get(n).parts]} for n in registry.names()]}


def _view(request) -> str:
    return "page" if request.query_params.get("view") == "page" else "json"


def _error(code: int, line: str) -> JSONResponse:
    """An error answer: the command's one line, its message, and the option it names (for the page)."""
    return error_response(code, line)


def _hide(text: str, tmp: str, upload_name: str | None) -> str:
    """A message without the request's private folder: the upload by its own name."""
    inside = os.path.join(tmp, "in")   # the folder a Check request's files are in: the folder the page chose
    text = text.replace(inside + os.sep, "").replace(inside, "the folder chosen").replace(tmp + os.sep, "")
    return text if upload_name is None else text.replace("upload-" + upload_name, upload_name)


class _private_folder:
    """A folder only this process can read (mkdtemp: mode 0700), removed with all it holds."""

    def __enter__(self) -> str:
        self.path = tempfile.mkdtemp(prefix="designer-web-")
        return self.path

    def __exit__(self, *exc) -> None:
        shutil.rmtree(self.path, ignore_errors=True)


async def _body(request: Request, limit: int) -> bytes:
    """The whole body, refused (:class:`TooLarge`) as soon as it passes ``limit`` bytes."""
    declared = request.headers.get("content-length")
    if declared is not None and declared.isdigit() and int(declared) > limit:
        raise TooLarge()
    chunks, n = [], 0
    async for chunk in request.stream():
        n += len(chunk)
        if n > limit:
            raise TooLarge()
        chunks.append(chunk)
    return b"".join(chunks)


#: most folders deep a Check upload's relative path may go (specs/decks/sub/x.cir is 3)
MAX_DEPTH = 8


def _relative(name) -> str:
    """An uploaded file's path relative to the folder chosen (``specs/decks/rc_ladder.cir``, as a browser gives
    a folder's files), every part a plain name (:func:`~designer.core.fileio.check_plain_name`): no ``..``, no
    absolute path, nothing outside the request's private folder; else a one-line refusal."""
    text = str(name or "").replace("\\", "/")
    parts = text.split("/")
    try:
        if text.startswith("/") or len(parts) > MAX_DEPTH + 1:
            raise DesignError("")
        for part in parts:
            check_plain_name(part, "file name")
    except DesignError:
        raise DesignError(f"file {text[:80]!r}: a path relative to the folder chosen, each part a plain name "
                          "(letters, digits and . _ - + = , @; no '..', no absolute path), as the spec names it") \
            from None
    return "/".join(parts)


def _write_inside(inside: str, rel: str) -> str:
    """The path of ``rel`` (checked by :func:`_relative`) under ``inside``, its folders made."""
    path = os.path.join(inside, *rel.split("/"))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    return path


def _plain(name, fallback: str) -> str:
    """An uploaded file's own name when it is a plain one, else ``fallback``."""
    base = os.path.basename(str(name or "").replace("\\", "/"))
    try:
        return check_plain_name(base, "file name")
    except DesignError:
        return fallback


async def _stream_to(request: Request, path: str, limit: int) -> None:
    declared = request.headers.get("content-length")
    if declared is not None and declared.isdigit() and int(declared) > limit:
        raise TooLarge()
    n = 0
    with open(path, "wb") as fh:
        async for chunk in request.stream():
            n += len(chunk)
            if n > limit:
                raise TooLarge()
            fh.write(chunk)


async def _multipart(request: Request, tmp: str, limit: int) -> tuple:
    """A multipart form streamed into ``tmp``: (files: field -> [(name, path)], fields: name -> text)."""
    from python_multipart import FormParser
    from python_multipart.multipart import parse_options_header
    declared = request.headers.get("content-length")
    if declared is not None and declared.isdigit() and int(declared) > limit:
        raise TooLarge()
    ctype, params = parse_options_header(request.headers.get("content-type", ""))
    boundary = params.get(b"boundary")
    if not boundary:
        raise DesignError("a multipart upload needs its boundary in the Content-Type header")
    files, fields = {}, {}
    uploads = os.path.join(tmp, "parts")
    os.mkdir(uploads)

    def on_field(field):
        key = field.field_name.decode("utf-8", "replace")
        _gather(fields, key, (field.value or b"").decode("utf-8", "replace"))

    def on_file(f):
        files.setdefault(f.field_name.decode("utf-8", "replace"), []).append(f)

    parser = FormParser(ctype.decode("latin-1"), on_field, on_file, boundary=boundary,
                        config={"UPLOAD_DIR": uploads, "MAX_MEMORY_FILE_SIZE": 1024 * 1024,
                                "UPLOAD_KEEP_FILENAME": False, "UPLOAD_KEEP_EXTENSIONS": False})
    n = 0
    try:
        async for chunk in request.stream():
            n += len(chunk)
            if n > limit:
                raise TooLarge()
            parser.write(chunk)
        parser.finalize()
    except TooLarge:
        raise
    except Exception as exc:   # python-multipart's own errors (a malformed form): the client's mistake
        raise DesignError(f"the multipart form cannot be read: {exc}") from None
    return files, fields


def _gather(options: dict, key: str, value: str) -> None:
    """A query's or form's field into ``options``: a name given twice or more is a list of its values, as an
    option that takes several (``?window=0&window=2m``) or repeats wants them."""
    if key not in options:
        options[key] = value
    elif isinstance(options[key], list):
        options[key].append(value)
    else:
        options[key] = [options[key], value]


def _save(f, path: str) -> None:
    """A part python-multipart kept (in memory or in the request's folder) as ``path``."""
    obj = f.file_object
    obj.seek(0)
    with open(path, "wb") as out:
        shutil.copyfileobj(obj, out)
    f.close()


async def _upload(request: Request, tmp: str, limit: int, field: str) -> tuple:
    """The capture (the body itself, options in the query string; or a multipart
    form whose first file is the capture, options in its other fields) written in
    ``tmp``: (path, its name as uploaded, options)."""
    ctype = request.headers.get("content-type", "")
    if ctype.startswith("multipart/form-data"):
        files, options = await _multipart(request, tmp, limit)
        parts = files.get(field) or next(iter(files.values()), None)
        if not parts:
            raise DesignError(f"the form has no file: send the capture as the field {field!r}")
        name = _plain(parts[0].file_name.decode("utf-8", "replace") if parts[0].file_name else "", "capture.csv")
        path = os.path.join(tmp, "upload-" + name)
        _save(parts[0], path)
    else:
        name = _plain(request.query_params.get("filename"), "capture.csv")
        path = os.path.join(tmp, "upload-" + name)
        options = {}
        for k, v in request.query_params.multi_items():
            if k not in ("view", "filename"):
                _gather(options, k, v)
        await _stream_to(request, path, limit)
    if os.path.getsize(path) == 0:
        raise DesignError("the capture is empty: send the file as the request's body or as a form's file")
    return path, name, options


async def _check_inputs(request: Request, tmp: str, limit: int) -> tuple:
    """check-design's spec and the files it names, in ``tmp/in``: a multipart form
    (a ``spec`` file, any other files by their own plain names, options as fields)
    or JSON ``{"spec": text, "files": {name: text}, "options": {...}}``: (the specs' paths relative to
    ``tmp/in``, the options)."""
    inside = os.path.join(tmp, "in")
    os.mkdir(inside)
    ctype = request.headers.get("content-type", "")
    if ctype.startswith("multipart/form-data"):
        files, fields = await _multipart(request, tmp, limit)
        spec = files.pop("spec", None)
        specs = []
        if spec:
            specs.append(_relative(spec[0].file_name.decode("utf-8", "replace") if spec[0].file_name
                                   else "spec.yaml"))
            _save(spec[0], _write_inside(inside, specs[0]))
        for parts in files.values():
            for f in parts:
                rel = _relative(f.file_name and f.file_name.decode("utf-8", "replace"))
                _save(f, _write_inside(inside, rel))
                if not spec and _is_spec(rel):   # a folder's specs, every one of them run
                    specs.append(rel)
        if not specs:
            raise DesignError("the form has no spec: send the spec file as the field 'spec', or a folder holding "
                              "specs (.yaml)")
        options = {k: v for k, v in fields.items() if k != "spec"}
        spec_text = fields.get("spec")
        if spec_text is not None:
            raise DesignError("send the spec as a file, not a text field")
        return sorted(specs), options
    body = req.parse_json(await _body(request, limit))
    form = ('the body must be {"spec": "<the spec file\'s text>", "files": {"decks/deck.cir": "..."}, "options": '
            '{...}}, or {"specs": ["specs/a.yaml"], "files": {"specs/a.yaml": "...", ...}}')
    if not isinstance(body, dict) or not (isinstance(body.get("spec"), str) or isinstance(body.get("specs"), list)):
        raise DesignError(form)
    files = body.get("files") or {}
    if not isinstance(files, dict) or not isinstance(body.get("options") or {}, dict) \
            or not isinstance(body.get("spec_name", ""), (str, type(None))):
        raise DesignError(form)
    for fname, text in files.items():
        if not isinstance(text, str):
            raise DesignError(f"file {str(fname)[:60]!r}: a plain name and its text")
        Path(_write_inside(inside, _relative(fname))).write_text(text, encoding="utf-8")
    if isinstance(body.get("spec"), str):
        name = _relative(body.get("spec_name") or "spec.yaml")
        specs = [name]
        Path(_write_inside(inside, name)).write_text(body["spec"], encoding="utf-8")
    else:
        specs = [_relative(p) if isinstance(p, str) else _relative(None) for p in body["specs"]]
        missing = [p for p in specs if p not in {_relative(f) for f in files}]
        if not specs or missing:
            raise DesignError(f"spec {missing[0]!r} is not among the files sent" if missing else form)
    return specs, body.get("options") or {}


def _is_spec(rel: str) -> bool:
    """Whether a file of a folder sent to Check is a spec to run (a YAML file)."""
    return rel.lower().endswith((".yaml", ".yml"))
