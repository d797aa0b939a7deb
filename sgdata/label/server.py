"""The labeling web app: a FastAPI app over the photo index and the label store, and its runner.

Routes (all same-origin, no CDN)::

    GET /                     the page (static/index.html); /static/app.js, app.css, favicon.svg
    GET /photos/<name>        a photo's bytes, looked up in the index (nothing else is served)
    GET /api/photos           photos in order (rescanned: new files appear), with their room,
                              box count and what keeps each from export; and skipped files
    GET /api/classes          catalog classes and mapped names, for the type-ahead
    GET /api/classes/unknown  ?name=...: the message for a name that is no class (closest names)
    GET /api/labels/<name>    a photo's labels, the relations proposed from its boxes, problems;
                              a never-saved photo's labels are the --detector's boxes, if any
    PUT /api/labels/<name>    save (JSON, <= 1 MiB, no unknown fields, the revision last seen)

The proposal rules run here (``sgdata.label.proposals``), and so does the detector of
``--detector`` (``sgdata.label.box_proposer``); the page shows what the API returns.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from importlib import resources
from pathlib import Path

from fastapi import FastAPI, HTTPException, Request
from fastapi.responses import FileResponse, JSONResponse, Response
from pydantic import ValidationError

from sgdata.errors import ConfigError
from sgdata.label.box_proposer import (
    DEFAULT_MIN_SCORE,
    BoxProposer,
    ProposedBox,
    open_proposer,
)
from sgdata.label.classes import ClassNames, load_class_names
from sgdata.label.models import LabeledObject, PhotoLabels
from sgdata.label.photos import DEFAULT_MAX_PIXELS, Photo, scan_photos, shown_pixels
from sgdata.label.proposals import DEFAULT_RULES, ProposalRules
from sgdata.label.review import problems, proposals_for, room_instances
from sgdata.label.store import ConflictError, LabelStore

__all__ = ["MAX_BODY", "create_app", "serve"]

MAX_BODY = 1 << 20  # bytes a save may send
LOOPBACK = ("127.0.0.1", "localhost", "::1")
# The page's own files: a fixed table, so no request path ever reaches the file system.
STATIC = {
    "index.html": "text/html; charset=utf-8",
    "app.js": "text/javascript; charset=utf-8",
    "app.css": "text/css; charset=utf-8",
    "favicon.svg": "image/svg+xml",
}
_HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff"}


def _static(name: str) -> Response:
    text = resources.files("sgdata.label").joinpath("static", name).read_bytes()
    headers = {**_HEADERS, "Content-Security-Policy": "default-src 'self'; img-src 'self'"}
    return Response(text, media_type=STATIC[name], headers=headers)


def host_name(header: str) -> str:
    """The host of a ``Host`` header without its port: ``[::1]:8765`` -> ``::1``."""
    if header.startswith("["):
        return header[1 : header.find("]")] if "]" in header else ""
    return header.rsplit(":", 1)[0] if header.count(":") == 1 else header


class _HostGuard:
    """Answer only requests whose ``Host`` is one of ``allowed`` (DNS-rebinding guard).

    Starlette's TrustedHostMiddleware cuts ``[::1]:port`` at the first colon; this one reads
    bracketed IPv6 hosts.
    """

    def __init__(self, app, allowed: tuple[str, ...]) -> None:
        self.app, self.allowed = app, set(allowed)

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] in ("http", "websocket"):
            headers = dict(scope["headers"])
            host = host_name(headers.get(b"host", b"").decode("latin-1"))
            if host not in self.allowed:
                await Response("Invalid host header", status_code=400)(scope, receive, send)
                return
        await self.app(scope, receive, send)


async def _read_body(request: Request) -> bytes:
    declared = request.headers.get("content-length")
    if declared is not None and (not declared.isdigit() or int(declared) > MAX_BODY):
        raise HTTPException(413, f"body over {MAX_BODY} bytes")
    body = bytearray()
    async for chunk in request.stream():
        body.extend(chunk)
        if len(body) > MAX_BODY:
            raise HTTPException(413, f"body over {MAX_BODY} bytes")
    return bytes(body)


def create_app(
    photos_dir: Path,
    out_dir: Path,
    *,
    class_map: Path | None = None,
    max_pixels: int = DEFAULT_MAX_PIXELS,
    rules: ProposalRules = DEFAULT_RULES,
    allowed_hosts: tuple[str, ...] | None = LOOPBACK,
    detector: Path | None = None,
    min_score: float = DEFAULT_MIN_SCORE,
) -> FastAPI:
    """The labeling app for the photos in ``photos_dir``, saving under ``out_dir/labels``.

    Args:
        class_map: a ``--classes`` TOML file; remembered in ``out_dir/labels`` for later runs
            and the export (None: the remembered one, if any).
        max_pixels: larger photos are skipped, with the reason shown in the page.
        allowed_hosts: ``Host`` header values to answer (DNS-rebinding guard); None: any.
        detector: a detector run (``sgdata.label.box_proposer``) whose boxes of score
            >= ``min_score`` fill each photo never saved, marked as proposed.

    Raises:
        ConfigError: ``photos_dir`` is not a directory, ``out_dir`` cannot be written, a bad
            class map, or a detector run that does not open.
    """
    store = LabelStore(out_dir)
    names = load_class_names(store.class_map(class_map))
    proposer = None
    if detector is not None:
        proposer = open_proposer(detector, min_score=min_score, known=names.all_names())
    session = _Session(
        photos_dir, store, names, rules=rules, max_pixels=max_pixels, proposer=proposer
    )
    app = FastAPI(title="sgdata label", docs_url=None, redoc_url=None, openapi_url=None)
    if allowed_hosts is not None:
        app.add_middleware(_HostGuard, allowed=allowed_hosts)
    _add_page_routes(app, session)
    _add_api_routes(app, session)
    return app


class _Session:
    """What the app's routes share: the label store, the class names and the photo index."""

    def __init__(
        self,
        photos_dir: Path,
        store: LabelStore,
        names: ClassNames,
        *,
        rules: ProposalRules,
        max_pixels: int,
        proposer: BoxProposer | None = None,
    ) -> None:
        self.photos_dir, self.store, self.names = photos_dir, store, names
        self.rules, self.max_pixels, self.proposer = rules, max_pixels, proposer
        self.index = scan_photos(photos_dir, max_pixels=max_pixels)  # replaced by each rescan
        self._scanning = threading.Lock()
        # (photo name, scan stamp) -> the detector's boxes: a photo is detected once per change
        self._detected: dict[tuple[str, tuple[int, int]], list[ProposedBox]] = {}

    def photo(self, name: str) -> Photo:
        """The indexed photo ``name``, or a 404."""
        photo = self.index.get(name)
        if photo is None:
            raise HTTPException(404, "no such photo")
        return photo

    def labels(self, name: str, saved: dict[str, PhotoLabels]) -> PhotoLabels:
        """The saved labels of photo ``name``; for a photo never saved, the detector's boxes
        (if any), marked as proposed, best first, with ids no saved photo uses (an id names
        one object of a room: carry over, not the detector, ties a box to another photo's).
        ``saved``: every saved photo's labels (:meth:`LabelStore.labeled`)."""
        labels = saved.get(name, PhotoLabels())
        if labels.revision or self.proposer is None:
            return labels
        photo = self.photo(name)
        key = (name, photo.stamp)
        if key not in self._detected:
            try:
                self._detected[key] = self.proposer(shown_pixels(photo))
            except ConfigError as exc:  # the page shows it; labeling by hand goes on
                raise HTTPException(500, str(exc)) from None
        first = 1 + max((o.id for other in saved.values() for o in other.objects), default=0)
        objects = [
            LabeledObject(
                id=k, class_name=b.class_name, box=list(b.box), proposed=round(b.score, 3)
            )
            for k, b in enumerate(self._detected[key], start=first)
        ]
        return labels.model_copy(update={"objects": objects})

    def payload(
        self, name: str, labels: PhotoLabels, saved: dict[str, PhotoLabels] | None = None
    ) -> dict:
        """A photo's labels as the page edits them, with proposals and what is still missing;
        ``saved`` as :meth:`labels` takes it (None: read now)."""
        saved = self.store.labeled() if saved is None else saved
        room = room_instances(saved, labels.room_id, name)
        return {
            "photo": name,
            "labels": labels.model_dump(mode="json"),
            "proposals": [p.to_dict() for p in proposals_for(labels, self.names, self.rules)],
            "problems": problems(labels, self.names, self.rules, room),
            # ids the room's other photos use: a new box takes a fresh one
            "room_ids": sorted(room),
            "detector": None
            if self.proposer is None
            else {"run": str(self.proposer.run), "min_score": self.proposer.min_score},
        }

    def listing(self) -> dict:
        """Every photo (rescanned: photos copied in while the server runs appear) with its
        labeling state, and the skipped files with the reason."""
        with self._scanning:
            self.index = scan_photos(
                self.photos_dir, max_pixels=self.max_pixels, previous=self.index
            )
        saved = self.store.labeled()
        rows = []
        for name, p in self.index.photos.items():
            labels = saved.get(name, PhotoLabels())
            room = room_instances(saved, labels.room_id, name)
            todo = problems(labels, self.names, self.rules, room)
            rows.append(
                {
                    "name": name,
                    "width": p.width,
                    "height": p.height,
                    "room_id": labels.room_id,
                    "objects": len(labels.objects),
                    "problems": todo,
                    "ready": not todo,
                }
            )
        skipped = [{"name": n, "reason": why} for n, why in self.index.skipped]
        return {"photos": rows, "skipped": skipped}

    def parse(self, found: Photo, body: bytes) -> PhotoLabels | JSONResponse:
        """The labels of a PUT body, or the 400 / 422 answer naming what is wrong."""
        try:
            raw = json.loads(body)
        except ValueError as exc:  # bad JSON, bad UTF-8, an integer of over 4,300 digits
            raise HTTPException(400, f"malformed JSON ({str(exc)[:200]})") from None
        except RecursionError:
            raise HTTPException(400, "malformed JSON (nested too deeply)") from None
        try:
            labels = PhotoLabels.model_validate_json(json.dumps(raw))
        except ValidationError as exc:
            errors = [f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors()]
            return JSONResponse({"detail": errors}, status_code=422)
        w, h = found.width, found.height
        outside = [o.id for o in labels.objects if o.box[2] > w or o.box[3] > h]
        if outside:
            detail = [f"objects {outside}: box outside the {found.width}x{found.height} photo"]
            return JSONResponse({"detail": detail}, status_code=422)
        known = set(self.names.all_names())
        unknown = sorted({o.class_name for o in labels.objects if o.class_name} - known)
        if unknown:
            detail = [self.names.unknown(n) for n in unknown]
            return JSONResponse({"detail": detail}, status_code=422)
        return labels


def _add_page_routes(app: FastAPI, session: _Session) -> None:
    """The page, its static files and the photos themselves."""

    @app.get("/")
    def page() -> Response:
        return _static("index.html")

    @app.get("/static/{name}")
    def static(name: str) -> Response:
        if name not in STATIC:
            raise HTTPException(404, "no such file")
        return _static(name)

    @app.get("/favicon.ico")
    def favicon() -> Response:
        return _static("favicon.svg")

    @app.get("/photos/{name}")
    def photo(name: str) -> FileResponse:
        found = session.photo(name)
        return FileResponse(found.path, media_type=f"image/{found.format}", headers=_HEADERS)


def _add_api_routes(app: FastAPI, session: _Session) -> None:
    """The JSON API the page talks to: photos, class names, a photo's labels."""
    names = session.names

    @app.get("/api/photos")
    def photos() -> JSONResponse:
        return JSONResponse(session.listing(), headers=_HEADERS)

    @app.get("/api/classes")
    def class_names() -> JSONResponse:
        return JSONResponse({"catalog": list(names.catalog), "mapped": names.mapped})

    @app.get("/api/classes/unknown")
    def unknown_class(name: str) -> JSONResponse:
        return JSONResponse({"message": names.unknown(name[:100])}, headers=_HEADERS)

    @app.get("/api/labels/{name}")
    def get_labels(name: str) -> JSONResponse:
        session.photo(name)
        saved = session.store.labeled()
        labels = session.labels(name, saved)
        return JSONResponse(session.payload(name, labels, saved), headers=_HEADERS)

    @app.put("/api/labels/{name}")
    async def put_labels(name: str, request: Request) -> JSONResponse:
        found = session.photo(name)
        if request.headers.get("content-type", "").split(";")[0].strip() != "application/json":
            raise HTTPException(415, "expected Content-Type: application/json")
        labels = session.parse(found, await _read_body(request))
        if isinstance(labels, JSONResponse):
            return labels
        try:
            stored = session.store.save(name, labels)
        except ConflictError as exc:
            return JSONResponse({"detail": str(exc), "revision": exc.revision}, status_code=409)
        return JSONResponse(session.payload(name, stored), headers=_HEADERS)


def serve(
    photos_dir: Path,
    out_dir: Path,
    *,
    host: str = "127.0.0.1",
    port: int = 8765,
    class_map: Path | None = None,
    max_pixels: int = DEFAULT_MAX_PIXELS,
    detector: Path | None = None,
    min_score: float = DEFAULT_MIN_SCORE,
    on_ready: Callable[[str], None] | None = None,
) -> None:
    """Run the labeling app with uvicorn until interrupted (Ctrl-C stops it cleanly).

    ``on_ready`` is called with the page's URL once the app is built, before serving.

    Raises:
        ConfigError: a bad photos directory, output directory or class map.
    """
    import uvicorn

    hosts = LOOPBACK if host in LOOPBACK else None
    app = create_app(
        photos_dir,
        out_dir,
        class_map=class_map,
        max_pixels=max_pixels,
        allowed_hosts=hosts,
        detector=detector,
        min_score=min_score,
    )
    config = uvicorn.Config(app, host=host, port=port, log_level="warning", lifespan="on")
    server = uvicorn.Server(config)
    if on_ready is not None:
        shown = f"[{host}]" if ":" in host else host
        on_ready(f"http://{shown}:{port}/")
    server.run()
