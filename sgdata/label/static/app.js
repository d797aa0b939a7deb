// sgdata label: draw boxes, pick classes, confirm relations; every change is saved at once.
"use strict";
const $ = (s) => document.querySelector(s);
const SVG = "http://www.w3.org/2000/svg";
const TYPES = ["on", "in", "proximity", "disjoint"];
// state.cur.revision is the last revision the server stored; undo snapshots hold labels only,
// so an undo while a save is in flight cannot bring back an old revision (a false 409).
const state = { photos: [], idx: -1, names: [], cur: null, selected: null, currentRel: null,
  undo: [], redo: [], saving: null, dirty: false, conflict: false };

const clone = (x) => JSON.parse(JSON.stringify(x));
const pairKey = (a, b) => Math.min(a, b) + "-" + Math.max(a, b);
let statusCount = 0; // how many statuses were shown: a save's "saved" keeps an error shown since it began
function setStatus(text, error) {
  statusCount += 1;
  const el = $("#status"); el.textContent = text; el.className = error ? "error" : "";
  el.dataset.state = error ? "error" : text;
}
async function api(path, options) {
  const r = await fetch(path, options);
  let body = null; try { body = await r.json(); } catch (e) { body = null; }
  return { ok: r.ok, status: r.status, body };
}

// ------------------------------------------------------------------ loading
async function init() {
  const classes = await api("/api/classes");
  state.names = [...classes.body.catalog, ...Object.keys(classes.body.mapped)];
  await refreshList();
  if (state.photos.length) await openPhoto(0); else setStatus("no photos in this directory", true);
}
// The server rescans the directory on every listing: photos copied in while labeling appear.
async function refreshList() {
  const r = await api("/api/photos");
  if (!r.ok) return;
  const name = state.cur && state.cur.name;
  state.photos = r.body.photos;
  if (name) state.idx = state.photos.findIndex((p) => p.name === name);
  const ul = $("#skipped"); ul.textContent = "";
  for (const s of r.body.skipped) {
    const li = document.createElement("li"); li.textContent = `${s.name}: ${s.reason}`; ul.append(li);
  }
  // Skipped files are problems to see while labeling (a truncated or oversized photo): say how many.
  const box = $("#skipped-box"), count = r.body.skipped.length;
  if (count > Number(box.dataset.count || 0)) box.open = true;
  box.dataset.count = count; box.hidden = count === 0;
  $("#skipped-box summary").textContent = `${count} skipped file(s)`;
  renderList();
}
function renderList() {
  const ol = $("#photos"); ol.textContent = "";
  state.photos.forEach((p, k) => {
    const li = document.createElement("li");
    li.dataset.name = p.name; li.dataset.ready = p.ready ? "yes" : "no";
    li.className = (k === state.idx ? "current" : "") + (p.ready ? " ready" : "");
    li.title = p.ready ? "ready to export" : p.problems.join("\n");
    li.innerHTML = `<span class="mark"></span><span></span> <span class="n"></span>`;
    li.children[0].textContent = p.ready ? "✓ " : "";
    li.children[1].textContent = p.name;
    li.children[2].textContent = `${p.room_id || ""} ${p.objects ? "· " + p.objects + " boxes" : ""}`;
    li.onclick = () => openPhoto(k);
    ol.append(li);
  });
  const ready = state.photos.filter((p) => p.ready).length;
  $("#ready-count").textContent = `${ready}/${state.photos.length} ready to export`;
}
async function flush() { while (state.saving) await state.saving; }
async function openPhoto(k) {
  if (k < 0 || k >= state.photos.length) return;
  await flush();
  const p = state.photos[k];
  const r = await api("/api/labels/" + encodeURIComponent(p.name));
  if (!r.ok) { setStatus(`${p.name}: ${r.body && r.body.detail}`, true); await refreshList(); return; }
  state.idx = k; state.selected = null; state.currentRel = null; state.undo = []; state.redo = [];
  state.conflict = false;
  const { revision, ...labels } = r.body.labels;
  state.cur = { name: p.name, width: p.width, height: p.height, revision, labels, proposals: r.body.proposals, problems: r.body.problems, roomIds: r.body.room_ids, detector: r.body.detector };
  const img = $("#photo");
  img.src = "/photos/" + encodeURIComponent(p.name);
  await img.decode().catch(() => {});
  $("#overlay").setAttribute("viewBox", `0 0 ${p.width} ${p.height}`);
  $("#overlay").setAttribute("preserveAspectRatio", "none");
  $("#title").textContent = `${p.name} (${k + 1}/${state.photos.length}, ${p.width}x${p.height})`;
  document.body.dataset.photo = p.name;
  renderList(); renderMeta(); render(); setStatus("loaded");
  $("#stage").focus();
  refreshList();
}

// ------------------------------------------------------------------ saving
function change(mutate) {
  if (state.conflict) { setStatus("changed in another tab: reload the page", true); return; }
  const before = clone(state.cur.labels);
  mutate(state.cur.labels);
  state.undo.push(before); state.redo = [];
  render(); save();
}
function save() {
  if (state.saving) { state.dirty = true; return; }
  const name = state.cur.name, cur = state.cur;
  const body = JSON.stringify({ ...cur.labels, revision: cur.revision });
  setStatus("saving");
  const began = statusCount;
  state.saving = (async () => {
    try {
      const r = await api("/api/labels/" + encodeURIComponent(name), {
        method: "PUT", headers: { "Content-Type": "application/json" }, body, keepalive: body.length < 60000 });
      if (r.ok) {
        cur.revision = r.body.labels.revision;
        cur.proposals = r.body.proposals; cur.problems = r.body.problems; cur.roomIds = r.body.room_ids;
        if (state.cur === cur) render();
        const p = state.photos.find((x) => x.name === name);
        if (p) {
          p.room_id = r.body.labels.room_id; p.objects = r.body.labels.objects.length;
          p.problems = r.body.problems; p.ready = r.body.problems.length === 0; renderList();
        }
        if (statusCount === began || $("#status").dataset.state !== "error") setStatus("saved");
      } else if (r.status === 409) {
        state.conflict = true; setStatus(r.body.detail + " (reload the page)", true);
      } else {
        setStatus("not saved: " + JSON.stringify(r.body && r.body.detail), true);
      }
    } catch (e) { setStatus("not saved: " + e, true); }
  })();
  state.saving.then(() => {
    state.saving = null;
    if (state.dirty && !state.conflict) { state.dirty = false; save(); }
  });
}

// ------------------------------------------------------------------ relations model
function relationItems() {
  const L = state.cur.labels, items = [], seen = new Set();
  for (const d of L.relations) {
    items.push({ src: d.src, dst: d.dst, type: d.type, status: d.type === "disjoint" ? "rejected" : "accepted" });
    seen.add(pairKey(d.src, d.dst));
  }
  const ids = new Set(L.objects.map((o) => o.id));
  for (const p of state.cur.proposals) {
    if (!seen.has(pairKey(p.src, p.dst)) && ids.has(p.src) && ids.has(p.dst)) items.push({ ...p, status: "pending" });
  }
  items.sort((a, b) => a.src - b.src || a.dst - b.dst);
  return items;
}
function currentItem() {
  return relationItems().find((it) => pairKey(it.src, it.dst) === state.currentRel) || null;
}
function decide(item, type, src, dst) {
  change((L) => {
    L.relations = L.relations.filter((d) => pairKey(d.src, d.dst) !== pairKey(item.src, item.dst));
    L.relations.push({ src: src ?? item.src, dst: dst ?? item.dst, type });
  });
}
function nextPending(step) {
  const items = relationItems();
  if (!items.length) return;
  const pending = items.filter((it) => it.status === "pending");
  const list = pending.length ? pending : items;
  const keys = items.map((it) => pairKey(it.src, it.dst));
  let at = keys.indexOf(state.currentRel);
  for (let n = 0; n < items.length; n++) {
    at = (at + step + items.length) % items.length;
    if (list.includes(items[at])) { state.currentRel = keys[at]; break; }
  }
  render();
}
function acceptAll(type) {
  const pending = relationItems().filter((it) => it.status === "pending" && it.type === type);
  if (!pending.length) return;
  change((L) => { for (const it of pending) L.relations.push({ src: it.src, dst: it.dst, type }); });
}

// ------------------------------------------------------------------ drawing
function el(tag, attrs, parent) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (parent) parent.append(e);
  return e;
}
const area = (o) => (o.box[2] - o.box[0]) * (o.box[3] - o.box[1]);
function scale() { return state.cur.width / ($("#overlay").getBoundingClientRect().width || 1); }
function render() {
  if (!state.cur) return;
  const s = scale(), L = state.cur.labels, byId = new Map(L.objects.map((o) => [o.id, o]));
  const boxes = $("#boxes"); boxes.textContent = "";
  for (const o of [...L.objects].sort((a, b) => area(b) - area(a))) {
    const [u1, v1, u2, v2] = o.box;
    const guess = o.proposed != null;
    const g = el("g", { class: "box" + (o.id === state.selected ? " selected" : "") + (guess ? " proposed" : ""), "data-id": o.id }, boxes);
    el("rect", { class: "body", x: u1, y: v1, width: u2 - u1, height: v2 - v1, "data-id": o.id }, g);
    const t = el("text", { x: u1 + 3 * s, y: v1 + 16 * s, "font-size": 14 * s, "stroke-width": 3 * s }, g);
    t.textContent = `${o.id} ${o.class_name || "?"}` + (guess ? ` ${o.proposed.toFixed(2)}?` : "");
    if (o.id === state.selected) {
      for (const [cx, cy, corner] of [[u1, v1, "nw"], [u2, v1, "ne"], [u1, v2, "sw"], [u2, v2, "se"]]) {
        el("rect", { class: "handle", x: cx - 5 * s, y: cy - 5 * s, width: 10 * s, height: 10 * s, "data-id": o.id, "data-corner": corner }, g);
      }
    }
    g.addEventListener("mouseenter", () => hot(o.id, true));
    g.addEventListener("mouseleave", () => hot(o.id, false));
  }
  const arrows = $("#arrows"); arrows.textContent = "";
  const list = $("#relations"); list.textContent = "";
  for (const it of relationItems()) {
    const a = byId.get(it.src), b = byId.get(it.dst);
    if (!a || !b) continue;
    const key = pairKey(it.src, it.dst), cur = key === state.currentRel;
    const [x1, y1] = [(a.box[0] + a.box[2]) / 2, (a.box[1] + a.box[3]) / 2];
    const [x2, y2] = [(b.box[0] + b.box[2]) / 2, (b.box[1] + b.box[3]) / 2];
    const g = el("g", { class: `rel ${it.type} ${it.status}${cur ? " current" : ""}`, "data-src": it.src, "data-dst": it.dst, "data-type": it.type, "data-status": it.status }, arrows);
    const both = it.type === "proximity" || it.type === "disjoint";
    // Only the arrow's label takes clicks: the line ends at box centres, which must select boxes.
    el("line", { class: "shown", x1, y1, x2, y2, "marker-end": "url(#arrow)", ...(both ? { "marker-start": "url(#arrow)" } : {}) }, g);
    const t = el("text", { class: "hit", x: (x1 + x2) / 2 + 4 * s, y: (y1 + y2) / 2 - 4 * s, "font-size": 13 * s, "stroke-width": 3 * s }, g);
    t.textContent = it.type + (it.status === "pending" ? "?" : "");
    t.addEventListener("pointerdown", (e) => { e.stopPropagation(); state.currentRel = key; render(); $("#stage").focus(); });
    const li = document.createElement("li");
    li.className = it.status + (cur ? " current" : ""); li.dataset.src = it.src; li.dataset.dst = it.dst;
    const arrow = both ? "⟷" : "→";
    li.textContent = `${it.src} ${a.class_name || "?"} ${arrow} ${it.type} ${it.dst} ${b.class_name || "?"} · ${it.status}`;
    li.onclick = () => { state.currentRel = key; render(); $("#stage").focus(); };
    list.append(li);
  }
  const ul = $("#box-list"); ul.textContent = "";
  for (const o of L.objects) {
    const li = document.createElement("li");
    li.dataset.id = o.id; li.className = (o.id === state.selected ? "selected" : "") + (o.proposed != null ? " proposed" : "");
    li.textContent = `${o.id} ${o.class_name || "?"} (${o.box[2] - o.box[0]}x${o.box[3] - o.box[1]})` +
      (o.proposed != null ? ` · proposed ${o.proposed.toFixed(2)}` : "");
    li.onclick = () => { state.selected = o.id; render(); $("#stage").focus(); };
    ul.append(li);
  }
  const pr = $("#problems"); pr.textContent = "";
  for (const text of state.cur.problems || []) {
    const li = document.createElement("li"); li.textContent = text; pr.append(li);
  }
  $("#ready").textContent = (state.cur.problems || []).length ? "not ready to export:" : "ready to export";
  const sel = byId.get(state.selected);
  const input = $("#class-input");
  input.disabled = !sel; $("#delete").disabled = !sel;
  $("#accept-box").disabled = !(sel && sel.proposed != null);
  const guesses = L.objects.filter((o) => o.proposed != null).length, det = state.cur.detector;
  $("#accept-boxes").disabled = !guesses;
  $("#proposed-note").textContent = guesses ? `${guesses} box(es) proposed` +
    (det ? ` by ${det.run} (score ≥ ${det.min_score})` : "") + ": Enter accepts the selected one, Del deletes it" : "";
  if (document.activeElement !== input) input.value = sel ? sel.class_name : "";
}
function hot(id, on) {
  document.querySelectorAll(`#arrows .rel[data-src="${id}"], #arrows .rel[data-dst="${id}"]`).forEach((g) => g.classList.toggle("hot", on));
  document.querySelectorAll(`#boxes .box[data-id="${id}"]`).forEach((g) => g.classList.toggle("hot", on));
}
function renderMeta() {
  const L = state.cur.labels;
  $("#room-id").value = L.room_id || ""; $("#room-type").value = L.room_type || "";
  $("#pose-layout").value = L.pose ? L.pose.layout : ""; $("#pose-i").value = L.pose ? L.pose.i : "";
  $("#pose-j").value = L.pose ? L.pose.j : ""; $("#pose-heading").value = L.pose ? String(L.pose.heading) : "";
}

// ------------------------------------------------------------------ mouse
function point(e) {
  const r = $("#overlay").getBoundingClientRect();
  const x = Math.round(((e.clientX - r.left) * state.cur.width) / r.width);
  const y = Math.round(((e.clientY - r.top) * state.cur.height) / r.height);
  return [Math.max(0, Math.min(state.cur.width, x)), Math.max(0, Math.min(state.cur.height, y))];
}
let drag = null;
$("#overlay").addEventListener("pointerdown", (e) => {
  if (!state.cur || e.button !== 0) return;
  $("#stage").focus();
  const [x, y] = point(e), t = e.target, L = state.cur.labels;
  const before = clone(L);
  // Boxes under the pointer, smallest first: a click picks the smallest, the next click the
  // one beneath it, so a box covered by a later, bigger box can still be selected.
  const under = L.objects.filter((o) => o.box[0] <= x && x <= o.box[2] && o.box[1] <= y && y <= o.box[3])
    .sort((a, b) => area(a) - area(b)).map((o) => o.id);
  if (t.dataset.corner) drag = { mode: "resize", id: Number(t.dataset.id), corner: t.dataset.corner, before };
  else if (state.selected !== null && under.includes(state.selected)) {
    const o = L.objects.find((o) => o.id === state.selected);
    const next = under[(under.indexOf(o.id) + 1) % under.length];
    drag = { mode: "move", id: o.id, x, y, box: [...o.box], before, click: next };
  } else {
    // On empty photo or an unselected box: a drag draws a new box (boxes inside boxes are
    // the usual case), a click without a drag selects the box under the pointer.
    // A fresh id for the room: ids name objects across the room's photos (carry over keeps them).
    const next = [...L.objects.map((o) => o.id), ...state.cur.roomIds].reduce((m, id) => Math.max(m, id + 1), 0);
    drag = { mode: "draw", id: next, x, y, before, added: false, click: under.length ? under[0] : null };
    state.selected = null;
  }
  $("#overlay").setPointerCapture(e.pointerId);
  render();
});
$("#overlay").addEventListener("pointermove", (e) => {
  if (!drag) return;
  const [x, y] = point(e), L = state.cur.labels, W = state.cur.width, H = state.cur.height;
  if (drag.mode === "draw") {
    const box = [Math.min(drag.x, x), Math.min(drag.y, y), Math.max(drag.x, x), Math.max(drag.y, y)];
    if (!drag.added) {
      if (box[2] - box[0] < 3 || box[3] - box[1] < 3) return;
      L.objects.push({ id: drag.id, class_name: "", box }); drag.added = true; state.selected = drag.id;
    }
    L.objects.find((o) => o.id === drag.id).box = box;
  } else if (drag.mode === "move") {
    const o = L.objects.find((o) => o.id === drag.id), b = drag.box;
    const dx = Math.max(-b[0], Math.min(W - b[2], x - drag.x)), dy = Math.max(-b[1], Math.min(H - b[3], y - drag.y));
    o.box = [b[0] + dx, b[1] + dy, b[2] + dx, b[3] + dy];
  } else {
    const o = L.objects.find((o) => o.id === drag.id), b = [...o.box];
    if (drag.corner.includes("w")) b[0] = Math.min(x, b[2] - 2); else b[2] = Math.max(x, b[0] + 2);
    if (drag.corner.includes("n")) b[1] = Math.min(y, b[3] - 2); else b[3] = Math.max(y, b[1] + 2);
    o.box = b;
  }
  render();
});
$("#overlay").addEventListener("pointerup", () => {
  if (!drag) return;
  const d = drag; drag = null;
  const changed = JSON.stringify(d.before) !== JSON.stringify(state.cur.labels);
  if (!changed && ((d.mode === "draw" && !d.added) || d.mode === "move") && d.click != null) {
    state.selected = d.click; render(); return;
  }
  if (changed) { state.undo.push(d.before); state.redo = []; render(); save(); }
  if (d.mode === "draw" && d.added) { const input = $("#class-input"); input.disabled = false; input.value = ""; input.focus(); suggest(); }
});

// ------------------------------------------------------------------ class type-ahead
let active = 0;
function matches(q) {
  q = q.trim().toLowerCase();
  if (!q) return [];
  const starts = state.names.filter((n) => n.toLowerCase().startsWith(q));
  const inside = state.names.filter((n) => !n.toLowerCase().startsWith(q) && n.toLowerCase().includes(q));
  return [...starts, ...inside].slice(0, 12);
}
function suggest() {
  const ul = $("#class-suggest"); ul.textContent = "";
  matches($("#class-input").value).forEach((n, k) => {
    const li = document.createElement("li"); li.textContent = n; li.className = k === active ? "active" : "";
    li.onmousedown = (e) => { e.preventDefault(); pick(n); };
    ul.append(li);
  });
}
function pick(name) {
  const id = state.selected;
  $("#class-suggest").textContent = "";
  if (id === null || !name) return;
  state.selected = null; // the next drag draws; click a box to select it again
  change((L) => { L.objects.find((o) => o.id === id).class_name = name; });
  $("#class-input").value = name; $("#stage").focus();
}
async function unknownClass(name) {
  const r = await api("/api/classes/unknown?name=" + encodeURIComponent(name));
  setStatus(r.ok ? r.body.message : `unknown class ${name}`, true);
}
$("#class-input").addEventListener("input", () => { active = 0; suggest(); });
$("#class-input").addEventListener("blur", () => { $("#class-suggest").textContent = ""; });
$("#class-input").addEventListener("keydown", (e) => {
  const found = matches(e.target.value);
  if (e.key === "ArrowDown") { active = Math.min(active + 1, found.length - 1); suggest(); e.preventDefault(); }
  else if (e.key === "ArrowUp") { active = Math.max(active - 1, 0); suggest(); e.preventDefault(); }
  else if (e.key === "Enter") {
    const typed = e.target.value.trim(), exact = state.names.find((n) => n === typed);
    if (found[active] || exact) pick(found[active] || exact);
    else if (typed) unknownClass(typed);
    e.preventDefault();
  }
  else if (e.key === "Escape") { $("#stage").focus(); }
  e.stopPropagation();
});

// ------------------------------------------------------------------ metadata
function readPose() {
  const v = (s) => $(s).value.trim();
  if (v("#pose-i") === "" || v("#pose-j") === "" || v("#pose-heading") === "") return null;
  return { layout: Number(v("#pose-layout") || 0), i: Number(v("#pose-i")), j: Number(v("#pose-j")), heading: Number(v("#pose-heading")) };
}
$("#room-id").addEventListener("change", (e) => change((L) => { L.room_id = e.target.value.trim() || null; }));
$("#room-type").addEventListener("change", (e) => change((L) => { L.room_type = e.target.value || null; }));
for (const s of ["#pose-layout", "#pose-i", "#pose-j", "#pose-heading"]) {
  $(s).addEventListener("change", () => change((L) => { L.pose = readPose(); }));
}
async function carryOver() {
  const room = state.cur.labels.room_id || (state.photos[state.idx - 1] || {}).room_id;
  if (!room) { setStatus("carry over: set the room id first", true); return; }
  for (let k = state.idx - 1; k >= 0; k--) {
    if (state.photos[k].room_id !== room) continue;
    const r = await api("/api/labels/" + encodeURIComponent(state.photos[k].name));
    const prev = r.body.labels, L0 = state.cur.labels;
    if ((L0.objects.length || L0.relations.length) &&
        !window.confirm(`Replace the ${L0.objects.length} box(es) of this photo with the ${prev.objects.length} of ${state.photos[k].name}?`)) {
      setStatus("carry over cancelled"); return;
    }
    change((L) => { L.room_id = room; L.room_type = prev.room_type; L.objects = prev.objects; L.relations = prev.relations; });
    renderMeta(); setStatus(`carried over ${prev.objects.length} boxes from ${state.photos[k].name}`);
    return;
  }
  setStatus(`carry over: no earlier photo of room ${room}`, true);
}

// ------------------------------------------------------------------ buttons and keys
$("#prev").onclick = () => openPhoto(state.idx - 1);
$("#next").onclick = () => openPhoto(state.idx + 1);
$("#carry").onclick = carryOver;
$("#delete").onclick = () => deleteSelected();
$("#accept-box").onclick = () => acceptBoxes([state.selected]);
$("#accept-boxes").onclick = () => acceptBoxes(state.cur.labels.objects.map((o) => o.id));
// A detector's box becomes a label only when accepted; edits keep it proposed.
function acceptBoxes(ids) {
  const chosen = state.cur.labels.objects.filter((o) => ids.includes(o.id) && o.proposed != null).map((o) => o.id);
  if (!chosen.length) return;
  change((L) => { for (const o of L.objects) if (chosen.includes(o.id)) delete o.proposed; });
  setStatus(`accepted ${chosen.length} box(es)`);
}
const selectedProposed = () => state.cur.labels.objects.some((o) => o.id === state.selected && o.proposed != null);
document.querySelectorAll("#accept-all button").forEach((b) => { b.onclick = () => acceptAll(b.dataset.type); });
function deleteSelected() {
  const id = state.selected;
  if (id === null) return;
  state.selected = null;
  change((L) => {
    L.objects = L.objects.filter((o) => o.id !== id);
    L.relations = L.relations.filter((d) => d.src !== id && d.dst !== id);
  });
}
function undoRedo(from, to) {
  if (!from.length || state.conflict) return;
  to.push(clone(state.cur.labels));
  state.cur.labels = from.pop();
  renderMeta(); render(); save();
}
function cycleBox(step) {
  const ids = state.cur.labels.objects.map((o) => o.id);
  if (!ids.length) return;
  const at = ids.indexOf(state.selected);
  state.selected = ids[at < 0 ? (step > 0 ? 0 : ids.length - 1) : (at + step + ids.length) % ids.length];
  render();
}
document.addEventListener("keydown", (e) => {
  const tag = (e.target.tagName || "").toLowerCase();
  if (tag === "input" || tag === "select" || !state.cur) return;
  const key = e.key.toLowerCase(), item = currentItem();
  if (e.ctrlKey || e.metaKey) {
    if (key === "z" && !e.shiftKey) undoRedo(state.undo, state.redo);
    else if (key === "y" || (key === "z" && e.shiftKey)) undoRedo(state.redo, state.undo);
    else return;
  } else if (e.key === "ArrowRight") openPhoto(state.idx + 1);
  else if (e.key === "ArrowLeft") openPhoto(state.idx - 1);
  else if (e.key === "Delete" || e.key === "Backspace") deleteSelected();
  else if (e.key === "Tab") nextPending(e.shiftKey ? -1 : 1);
  else if (e.key === "Enter" && selectedProposed()) acceptBoxes([state.selected]);
  else if (e.key === "Escape") { state.selected = null; state.currentRel = null; render(); }
  else if (key === "c") carryOver();
  else if (key === "n") cycleBox(e.shiftKey ? -1 : 1);
  else if (item && e.key === "Enter") { decide(item, item.type === "disjoint" ? "disjoint" : item.type); nextPending(1); }
  else if (item && (key === "o" || key === "i" || key === "p")) { decide(item, { o: "on", i: "in", p: "proximity" }[key]); nextPending(1); }
  else if (item && key === "d") { decide(item, "disjoint"); nextPending(1); }
  else if (item && key === "r" && (item.type === "on" || item.type === "in")) { decide(item, item.type, item.dst, item.src); }
  else if (item && key === "a") acceptAll(item.type);
  else return;
  e.preventDefault();
});
window.addEventListener("resize", render);
window.addEventListener("focus", refreshList);
init();
