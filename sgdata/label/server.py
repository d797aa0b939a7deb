"""The labeling web app: a FastAPI app over the photo index and the label store, and its runner.

Routes (all same-origin, no CDN)::

    GET /                     the page (static/index.html); /static/app.js, /static/app.css
    GET /photos/<name>        a photo's bytes, looked up in the index (nothing else is served)
    GET /api/photos           photos in order, with their room and box counts, and skipped files
    GET /api/classes          catalog classes and mapped names, for the type-ahead
    GET /api/labels/<name>    a photo's labels and the relations proposed from its boxes
    PUT /api/labels/<name>    save (JSON, <= 1 MiB, no unknown fields, the revision last seen)

The proposal rules run here (``sgdata.label.proposals``); the page shows what the API returns.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from importlib import resources
from pathlib import Path

from fastapi import FastAPI, HTTPException, Request
from fastapi.responses import FileResponse, JSONResponse, Response
from pydantic import ValidationError
from starlette.middleware.trustedhost import TrustedHostMiddleware

from sgdata.label.classes import ClassNames, load_class_names
from sgdata.label.models import PhotoLabels
from sgdata.label.photos import PhotoIndex, scan_photos
from sgdata.label.proposals import DEFAULT_RULES, ProposalRules, propose_relations
from sgdata.label.store import ConflictError, LabelStore

__all__ = ["MAX_BODY", "create_app", "serve"]

MAX_BODY = 1 << 20  # bytes a save may send
LOOPBACK = ("127.0.0.1", "localhost", "::1")
# The page's own files: a fixed table, so no request path ever reaches the file system.
STATIC = {
    "index.html": "text/html; charset=utf-8",
    "app.js": "text/javascript; charset=utf-8",
    "app.css": "text/css; charset=utf-8",
}
_HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff"}


def _static(name: str) -> Response:
    text = resources.files("sgdata.label").joinpath("static", name).read_bytes()
    headers = {**_HEADERS, "Content-Security-Policy": "default-src 'self'; img-src 'self'"}
    return Response(text, media_type=STATIC[name], headers=headers)


def _payload(name: str, labels: PhotoLabels, rules: ProposalRules) -> dict:
    boxes = {o.id: o.box for o in labels.objects}
    return {
        "photo": name,
        "labels": labels.model_dump(mode="json"),
        "proposals": [p.to_dict() for p in propose_relations(boxes, rules)],
    }


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
    classes: ClassNames | None = None,
    rules: ProposalRules = DEFAULT_RULES,
    allowed_hosts: tuple[str, ...] | None = LOOPBACK,
) -> FastAPI:
    """The labeling app for the photos in ``photos_dir``, saving under ``out_dir/labels``.

    Args:
        allowed_hosts: ``Host`` header values to answer (DNS-rebinding guard); None: any.

    Raises:
        ConfigError: ``photos_dir`` is not a directory, or ``out_dir`` cannot be written.
    """
    index: PhotoIndex = scan_photos(photos_dir)
    store = LabelStore(out_dir)
    names = classes or load_class_names()

    app = FastAPI(title="sgdata label", docs_url=None, redoc_url=None, openapi_url=None)
    if allowed_hosts is not None:
        app.add_middleware(TrustedHostMiddleware, allowed_hosts=list(allowed_hosts))

    def photo_or_404(name: str):
        photo = index.get(name)
        if photo is None:
            raise HTTPException(404, "no such photo")
        return photo

    @app.get("/")
    def page() -> Response:
        return _static("index.html")

    @app.get("/static/{name}")
    def static(name: str) -> Response:
        if name not in STATIC:
            raise HTTPException(404, "no such file")
        return _static(name)

    @app.get("/photos/{name}")
    def photo(name: str) -> FileResponse:
        found = photo_or_404(name)
        return FileResponse(found.path, media_type=f"image/{found.format}", headers=_HEADERS)

    @app.get("/api/photos")
    def photos() -> JSONResponse:
        saved = store.labeled()
        rows = []
        for name, p in index.photos.items():
            labels = saved.get(name)
            rows.append(
                {
                    "name": name,
                    "width": p.width,
                    "height": p.height,
                    "room_id": labels.room_id if labels else None,
                    "objects": len(labels.objects) if labels else 0,
                }
            )
        skipped = [{"name": n, "reason": why} for n, why in index.skipped]
        return JSONResponse({"photos": rows, "skipped": skipped}, headers=_HEADERS)

    @app.get("/api/classes")
    def class_names() -> JSONResponse:
        return JSONResponse({"catalog": list(names.catalog), "mapped": names.mapped})

    @app.get("/api/labels/{name}")
    def get_labels(name: str) -> JSONResponse:
        photo_or_404(name)
        return JSONResponse(_payload(name, store.load(name), rules), headers=_HEADERS)

    @app.put("/api/labels/{name}")
    async def put_labels(name: str, request: Request) -> JSONResponse:
        found = photo_or_404(name)
        if request.headers.get("content-type", "").split(";")[0].strip() != "application/json":
            raise HTTPException(415, "expected Content-Type: application/json")
        body = await _read_body(request)
        try:
            raw = json.loads(body)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise HTTPException(400, f"malformed JSON ({exc})") from None
        try:
            labels = PhotoLabels.model_validate_json(json.dumps(raw))
        except ValidationError as exc:
            problems = [f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors()]
            return JSONResponse({"detail": problems}, status_code=422)
        w, h = found.width, found.height
        outside = [o.id for o in labels.objects if o.box[2] > w or o.box[3] > h]
        if outside:
            detail = [f"objects {outside}: box outside the {found.width}x{found.height} photo"]
            return JSONResponse({"detail": detail}, status_code=422)
        unknown = sorted(
            {o.class_name for o in labels.objects if o.class_name} - {n for n in names.all_names()}
        )
        if unknown:
            return JSONResponse({"detail": [f"unknown classes {unknown}"]}, status_code=422)
        try:
            stored = store.save(name, labels)
        except ConflictError as exc:
            return JSONResponse({"detail": str(exc), "revision": exc.revision}, status_code=409)
        return JSONResponse(_payload(name, stored, rules), headers=_HEADERS)

    return app


def serve(
    photos_dir: Path,
    out_dir: Path,
    *,
    host: str = "127.0.0.1",
    port: int = 8765,
    class_map: Path | None = None,
    on_ready: Callable[[str], None] | None = None,
) -> None:
    """Run the labeling app with uvicorn until interrupted (Ctrl-C stops it cleanly).

    ``on_ready`` is called with the page's URL once the app is built, before serving.

    Raises:
        ConfigError: a bad photos directory, output directory or class map.
    """
    import uvicorn

    classes = load_class_names(class_map)
    hosts = LOOPBACK if host in LOOPBACK else None
    app = create_app(photos_dir, out_dir, classes=classes, allowed_hosts=hosts)
    config = uvicorn.Config(app, host=host, port=port, log_level="warning", lifespan="on")
    server = uvicorn.Server(config)
    if on_ready is not None:
        shown = f"[{host}]" if ":" in host else host
        on_ready(f"http://{shown}:{port}/")
    server.run()
