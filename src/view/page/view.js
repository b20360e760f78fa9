// emaki view's page: reads /api/outputs (polled, so frames appear as a run writes them) and
// shows one sequence of output A (and B) at a time. Its state lives in the URL's hash
// (#frame=N&layer=NAME&overlay=NAME&compare=a|b|wipe|side&wipe=0.5&bare=1), so a link or a test
// opens the page on a given frame and layer.
"use strict";

const state = { frame: null, layer: "composite", overlay: "", compare: "wipe", wipe: 0.5,
                bare: false, playing: false };
let outputs = [];

const $ = (id) => document.getElementById(id);

function readHash() {
  const h = new URLSearchParams(location.hash.slice(1));
  if (h.has("frame")) state.frame = parseInt(h.get("frame"), 10);
  if (h.has("layer")) state.layer = h.get("layer");
  if (h.has("overlay")) state.overlay = h.get("overlay");
  if (h.has("compare")) state.compare = h.get("compare");
  if (h.has("wipe")) state.wipe = Math.min(1, Math.max(0, parseFloat(h.get("wipe"))));
  state.bare = h.get("bare") === "1";
}

function writeHash() {
  const h = new URLSearchParams();
  if (state.frame !== null) h.set("frame", state.frame);
  h.set("layer", state.layer);
  if (state.overlay) h.set("overlay", state.overlay);
  if (outputs.length > 1) h.set("compare", state.compare), h.set("wipe", state.wipe);
  if (state.bare) h.set("bare", "1");
  history.replaceState(null, "", "#" + h.toString());
}

function sequence(output, name) {
  return output ? output.sequences.find((s) => s.name === name) : undefined;
}

// The frames of the shown layer, over A and B.
function frames() {
  const all = new Set();
  for (const o of outputs) for (const f of (sequence(o, state.layer) || { frames: [] }).frames)
    all.add(f);
  return [...all].sort((a, b) => a - b);
}

function fileUrl(index, seq, frame) {
  const i = seq ? seq.frames.indexOf(frame) : -1;
  if (i < 0) return null;
  return "files/" + index + "/" + seq.files[i].split("/").map(encodeURIComponent).join("/") +
         "?t=" + seq.stamps[i];
}

function setImage(img, url) {
  if (!url) return img.removeAttribute("src");
  if (img.getAttribute("src") !== url) img.src = url;
}

function renderLayers() {
  const nav = $("layers");
  const names = [];
  for (const o of outputs) for (const s of o.sequences) if (!names.includes(s.name)) names.push(s.name);
  if (!names.includes(state.layer) && names.length) state.layer = names[0];
  if (nav.dataset.names !== names.join("\n")) {
    nav.dataset.names = names.join("\n");
    nav.replaceChildren(...names.map((n) => {
      const b = document.createElement("button");
      b.textContent = n;
      b.dataset.layer = n;
      b.onclick = () => { state.layer = n; update(); };
      return b;
    }));
    const overlay = $("overlay");
    overlay.replaceChildren(new Option("none", ""), ...names.map((n) => new Option(n, n)));
  }
  for (const b of nav.children) b.classList.toggle("on", b.dataset.layer === state.layer);
  $("overlay").value = state.overlay;
}

function renderFrame() {
  const list = frames();
  const scrubber = $("scrubber");
  scrubber.max = Math.max(0, list.length - 1);
  if (list.length && (state.frame === null || !list.includes(state.frame)))
    state.frame = list.reduce((best, f) =>
        state.frame !== null && Math.abs(f - state.frame) < Math.abs(best - state.frame) ? f : best,
        list[0]);
  scrubber.value = Math.max(0, list.indexOf(state.frame));
  $("frame-number").textContent = state.frame === null ? "-" : state.frame;
  $("frame-count").textContent = list.length ? "(" + list.length + " frames)" : "(no frames yet)";
  ["a", "b"].forEach((side, index) => {
    const o = outputs[index];
    setImage($("img-" + side), o ? fileUrl(index, sequence(o, state.layer), state.frame) : null);
    setImage($("overlay-" + side),
             o && state.overlay ? fileUrl(index, sequence(o, state.overlay), state.frame) : null);
  });
  renderCompare();
}

function renderCompare() {
  const two = outputs.length > 1;
  $("compare-label").hidden = !two;
  $("compare").value = state.compare;
  const mode = two ? state.compare : "a";
  const stage = $("stage");
  stage.classList.toggle("wipe", mode === "wipe");
  $("pane-a").hidden = mode === "b";
  $("pane-b").hidden = !two || mode === "a";
  const b = $("pane-b");
  const w = $("img-a").naturalWidth || $("img-a").width;
  b.style.clipPath = mode === "wipe" ? "inset(0 0 0 " + (state.wipe * 100) + "%)" : "";
  const line = $("wipe-line");
  line.style.left = $("pane-a").offsetLeft + state.wipe * w + "px";
  line.style.height = ($("img-a").height || 0) + "px";
}

function renderInfo() {
  const sheets = outputs.filter((o) => o.contact_sheet).map((o, i) => {
    const img = document.createElement("img");
    img.src = "files/" + i + "/" + o.contact_sheet + "?t=" + o.contact_sheet_stamp;
    img.alt = "contact sheet of " + o.folder;
    return img;
  });
  const box = $("contact-sheets");
  const key = sheets.map((s) => s.src).join();
  if (box.dataset.key !== key) box.dataset.key = key, box.replaceChildren(...sheets);
  const parts = [];
  outputs.forEach((o, i) => {
    for (const m of o.manifests) {
      const h = document.createElement("h4");
      h.textContent = (outputs.length > 1 ? "ABCDEFGHIJ"[i] + ": " : "") + o.folder + "/" + m.folder;
      const pre = document.createElement("pre");
      pre.textContent = m.text;
      parts.push(h, pre);
    }
  });
  const text = parts.map((p) => p.textContent).join("\n");
  if ($("manifests").dataset.text !== text)
    $("manifests").dataset.text = text, $("manifests").replaceChildren(...parts);
}

function update() {
  document.body.classList.toggle("bare", state.bare);
  renderLayers();
  renderFrame();
  writeHash();
}

function step(delta) {
  const list = frames();
  if (!list.length) return;
  const i = Math.max(0, list.indexOf(state.frame));
  state.frame = list[(i + delta + list.length) % list.length];
  update();
}

async function poll() {
  try {
    const r = await fetch("api/outputs", { cache: "no-store" });
    outputs = (await r.json()).outputs;
    const s = await (await fetch("api/status", { cache: "no-store" })).json();
    $("status").textContent = s.message || "";
    update();
    renderInfo();
    document.body.dataset.loaded = "1";
  } catch (e) {
    $("status").textContent = "server not answering";
  }
}

// emaki lookdev's status (a few bytes) is asked for ten times a second, and the outputs as
// soon as its run count moves on, so a new preview frame shows within 0.1 s of being written;
// the outputs themselves are listed once a second (a farm or `emaki run` writing frames).
let generation;
async function pollStatus() {
  try {
    const s = await (await fetch("api/status", { cache: "no-store" })).json();
    $("status").textContent = s.message || "";
    if (s.generation === undefined || s.generation === generation) return;
    generation = s.generation;
    await poll();
  } catch (e) {}
}

function keys(e) {
  if (e.target.tagName === "SELECT" || e.target.tagName === "INPUT" && e.target.type !== "range")
    return;
  if (e.key === " ") state.playing = !state.playing, e.preventDefault();
  else if (e.key === "ArrowRight") step(1), e.preventDefault();
  else if (e.key === "ArrowLeft") step(-1), e.preventDefault();
  $("play").innerHTML = state.playing ? "&#10074;&#10074;" : "&#9654;";
}

readHash();
window.addEventListener("hashchange", () => { readHash(); update(); });
document.addEventListener("keydown", keys);
$("play").onclick = () => keys({ key: " ", target: document.body, preventDefault() {} });
$("scrubber").oninput = (e) => { state.frame = frames()[+e.target.value]; update(); };
$("overlay").onchange = (e) => { state.overlay = e.target.value; update(); };
$("compare").onchange = (e) => { state.compare = e.target.value; update(); };
$("stage").addEventListener("pointermove", (e) => {
  if (state.compare !== "wipe" || !(e.buttons & 1)) return;
  const r = $("img-a").getBoundingClientRect();
  state.wipe = Math.min(1, Math.max(0, (e.clientX - r.left) / r.width));
  renderCompare();
});
$("img-a").onload = renderCompare;
setInterval(() => { if (state.playing) step(1); }, 1000 / 12);
setInterval(poll, 1000);
setInterval(pollStatus, 100);
poll();
