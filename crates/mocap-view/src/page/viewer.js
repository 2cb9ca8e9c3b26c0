// mocap viewer: plays the motions of /scene.json as 3D skeletons on a 2D
// canvas with a perspective camera. No library, no network beyond this
// server: the page works offline.
//
// The scene format is documented in crates/mocap-view/src/server.rs.
// Coordinates are metres, y up. Motions share one clock: at time t a motion
// shows frame floor(t / frame_time), held on its last frame when shorter.
"use strict";

(function () {
  const canvas = document.getElementById("view");
  const ctx = canvas.getContext("2d");
  const el = (id) => document.getElementById(id);
  const playButton = el("play"), scrubber = el("scrubber"), frameLabel = el("frame-label");
  const speedSelect = el("speed"), loopBox = el("loop"), layoutSelect = el("layout");
  const colourSelect = el("colour-by"), followBox = el("follow"), tooltip = el("tooltip");

  const FOV = 45 * Math.PI / 180;
  const NEAR = 0.05;
  const GAP = 0.3; // metres between figures side by side

  let scene = null;         // the parsed scene.json
  let bounds = [];          // per motion: {min:[x,y,z], max:[x,y,z]}
  let offsets = [];         // per motion: x of its spot in the row (side by side)
  let roots = [];           // per motion: the point kept over its spot (the hips)
  let reaches = [];         // per motion: farthest horizontal distance of a point from the root
  let floorY = 0;
  let clock = { t: 0, duration: 0, step: 1 / 30, playing: false, last: 0 };
  let camera = { yaw: 0.5, pitch: 0.25, distance: 4, target: [0, 1, 0] };
  let hidden = [];          // per motion: hidden by its legend box
  let drawnPoints = [];     // screen positions of the last drawn frame, for hovering
  let hover = null;         // {motion, point}
  let frameTicks = 0;       // frames drawn while playing (for tests)

  // ---------- loading ----------

  fetch("scene.json", { cache: "no-store" })
    .then((r) => { if (!r.ok) throw new Error("scene.json: HTTP " + r.status); return r.json(); })
    .then(start)
    .catch((e) => {
      const box = el("error");
      box.textContent = "Could not load the motions: " + e.message;
      box.style.display = "flex";
    });

  function start(data) {
    scene = data;
    hidden = scene.motions.map(() => false);
    bounds = scene.motions.map(motionBounds);
    roots = scene.motions.map(rootPoint);
    reaches = scene.motions.map(horizontalReach);
    floorY = Math.min(...bounds.map((b) => b.min[1]));
    const steps = scene.motions.map((m) => m.frame_time);
    clock.step = Math.min(...steps);
    clock.duration = Math.max(...scene.motions.map((m) => (m.frame_count - 1) * m.frame_time), 0);
    scrubber.max = String(Math.round(clock.duration / clock.step));
    buildLegend();
    if (!scene.motions.some((m) => m.confidence)) {
      colourSelect.querySelector('option[value="confidence"]').disabled = true;
    } else {
      colourSelect.value = "confidence";
    }
    updateLayout();
    fitCamera();
    resize();
    bindControls();
    document.body.dataset.ready = "1";
    requestAnimationFrame(tick);
  }

  // The box around every shown point of every frame.
  function motionBounds(m) {
    const p = m.positions, n = m.names.length;
    const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p.length; i += 3) {
      if (!m.shown[(i / 3) % n]) continue;
      for (let k = 0; k < 3; k++) {
        if (p[i + k] < min[k]) min[k] = p[i + k];
        if (p[i + k] > max[k]) max[k] = p[i + k];
      }
    }
    if (min[0] === Infinity) return { min: [0, 0, 0], max: [0, 0, 0] };
    return { min, max };
  }

  function horizontalReach(m, i) {
    const n = m.names.length, p = m.positions, root = roots[i];
    let reach = 0;
    for (let f = 0; f < m.frame_count; f++) {
      const r = (f * n + root) * 3;
      for (let q = 0; q < n; q++) {
        if (!m.shown[q]) continue;
        const k = (f * n + q) * 3;
        reach = Math.max(reach, Math.hypot(p[k] - p[r], p[k + 2] - p[r + 2]));
      }
    }
    return reach;
  }

  function sideBySide() {
    return layoutSelect.value === "side";
  }

  // Side by side, each motion stands on its own spot of a row with its hips
  // kept over it (as on a treadmill), so that takes that travel differently
  // still stand next to each other (as mocap_view::render does).
  function updateLayout() {
    const spacing = 2 * Math.max(...reaches) + GAP;
    offsets = scene.motions.map((m, i) => (sideBySide() ? (i - (scene.motions.length - 1) / 2) * spacing : 0));
  }

  function sceneBox() {
    const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
    if (sideBySide()) {
      const reach = Math.max(...reaches);
      return {
        min: [Math.min(...offsets) - reach, Math.min(...bounds.map((b) => b.min[1])), -reach],
        max: [Math.max(...offsets) + reach, Math.max(...bounds.map((b) => b.max[1])), reach],
      };
    }
    scene.motions.forEach((m, i) => {
      for (let k = 0; k < 3; k++) {
        const shift = k === 0 ? offsets[i] : 0;
        min[k] = Math.min(min[k], bounds[i].min[k] + shift);
        max[k] = Math.max(max[k], bounds[i].max[k] + shift);
      }
    });
    return { min, max };
  }

  // Frames the whole scene; a take that travels far (a walk) is followed
  // instead, framed around the figure, so that it is not drawn tiny.
  function fitCamera() {
    const box = sceneBox();
    const centre = [0, 1, 2].map((k) => (box.min[k] + box.max[k]) / 2);
    const height = Math.max(0.5, box.max[1] - box.min[1]);
    const travel = Math.hypot(box.max[0] - box.min[0], box.max[2] - box.min[2]);
    const spread = sideBySide() ? (Math.max(...offsets) - Math.min(...offsets)) / 2 : 0;
    followBox.checked = !sideBySide() && travel > 2.5 * height;
    const radius = followBox.checked
      ? 0.7 * height + spread
      : Math.max(0.5, Math.hypot(box.max[0] - box.min[0], height, box.max[2] - box.min[2]) / 2);
    camera.target = centre;
    camera.distance = radius / Math.sin(FOV / 2) * 1.05;
    camera.yaw = 0.55;
    camera.pitch = 0.35;
  }

  // ---------- the clock ----------

  function frameOf(m, t) {
    return Math.max(0, Math.min(m.frame_count - 1, Math.floor(t / m.frame_time + 1e-6)));
  }

  function setTime(t) {
    clock.t = Math.max(0, Math.min(clock.duration, t));
    scrubber.value = String(Math.round(clock.t / clock.step));
  }

  function setPlaying(on) {
    if (on && clock.t >= clock.duration - 1e-9) setTime(0);
    clock.playing = on;
    clock.last = performance.now();
    playButton.textContent = on ? "Pause" : "Play";
  }

  function tick(now) {
    if (clock.playing) {
      const dt = Math.min(0.25, (now - clock.last) / 1000) * Number(speedSelect.value);
      clock.last = now;
      let t = clock.t + dt;
      if (t > clock.duration) {
        if (loopBox.checked && clock.duration > 0) {
          t = t % (clock.duration + clock.step);
        } else {
          t = clock.duration;
          setPlaying(false);
        }
      }
      setTime(t);
      frameTicks++;
    }
    draw();
    requestAnimationFrame(tick);
  }

  // ---------- the camera ----------

  function eye() {
    const c = Math.cos(camera.pitch), d = camera.distance, t = camera.target;
    return [t[0] + d * c * Math.sin(camera.yaw), t[1] + d * Math.sin(camera.pitch), t[2] + d * c * Math.cos(camera.yaw)];
  }

  function basis() {
    const e = eye();
    const f = normalize(sub(camera.target, e));
    const r = normalize(cross(f, [0, 1, 0]));
    const u = cross(r, f);
    return { e, f, r, u };
  }

  function toCamera(b, p) {
    const d = sub(p, b.e);
    return [dot(d, b.r), dot(d, b.u), dot(d, b.f)];
  }

  function focal() {
    return (canvas.height / 2) / Math.tan(FOV / 2);
  }

  function project(c) {
    const f = focal();
    return [canvas.width / 2 + f * c[0] / c[2], canvas.height / 2 - f * c[1] / c[2]];
  }

  // Cuts a segment (camera space) at the near plane; null when all behind.
  function clipNear(a, b) {
    if (a[2] < NEAR && b[2] < NEAR) return null;
    if (a[2] >= NEAR && b[2] >= NEAR) return [a, b];
    const s = (NEAR - a[2]) / (b[2] - a[2]);
    const m = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), NEAR];
    return a[2] < NEAR ? [m, b] : [a, m];
  }

  // ---------- drawing ----------

  function confidenceColour(c) {
    return "hsl(" + Math.round(120 * c) + ",85%," + (c > 0.5 ? 40 : 45) + "%)";
  }

  // Where a point is drawn in the current layout.
  function pointPosition(m, i, frame, point) {
    const n = m.names.length, k = (frame * n + point) * 3;
    if (!sideBySide()) return [m.positions[k], m.positions[k + 1], m.positions[k + 2]];
    const r = (frame * n + roots[i]) * 3;
    return [m.positions[k] - m.positions[r] + offsets[i], m.positions[k + 1], m.positions[k + 2] - m.positions[r + 2]];
  }

  // Where a point is in the file (metres).
  function rawPosition(m, frame, point) {
    const k = (frame * m.names.length + point) * 3;
    return [m.positions[k], m.positions[k + 1], m.positions[k + 2]];
  }

  function pointConfidence(m, frame, point) {
    if (!m.confidence) return null;
    let j = point;
    while (j >= m.joint_count) j = m.parents[j];
    return m.confidence[frame * m.joint_count + j];
  }

  function follow() {
    // Keep the horizontal centre of the visible roots in view.
    let sx = 0, sz = 0, n = 0;
    scene.motions.forEach((m, i) => {
      if (hidden[i] || m.frame_count === 0) return;
      const p = pointPosition(m, i, frameOf(m, clock.t), rootPoint(m));
      sx += p[0]; sz += p[2]; n++;
    });
    if (n > 0) { camera.target[0] = sx / n; camera.target[2] = sz / n; }
  }

  function rootPoint(m) {
    // The first shown point not held by a bone: the hips of most rigs (as
    // ViewMotion::body_root).
    for (let p = 0; p < m.names.length; p++) if (m.shown[p] && !m.bones[p]) return p;
    return 0;
  }

  function drawGrid(b) {
    const box = sceneBox();
    const margin = 1;
    const x0 = Math.floor(box.min[0] - margin), x1 = Math.ceil(box.max[0] + margin);
    const z0 = Math.floor(box.min[2] - margin), z1 = Math.ceil(box.max[2] + margin);
    const line = (p, q, major) => {
      const seg = clipNear(toCamera(b, p), toCamera(b, q));
      if (!seg) return;
      const a = project(seg[0]), c = project(seg[1]);
      ctx.strokeStyle = major ? "#b9b9b4" : "#dcdcd8";
      ctx.lineWidth = major ? 1.2 : 1;
      ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(c[0], c[1]); ctx.stroke();
    };
    for (let x = x0; x <= x1 + 1e-9; x += 0.5) line([x, floorY, z0], [x, floorY, z1], Math.abs(x - Math.round(x)) < 1e-6);
    for (let z = z0; z <= z1 + 1e-9; z += 0.5) line([x0, floorY, z], [x1, floorY, z], Math.abs(z - Math.round(z)) < 1e-6);
  }

  function draw() {
    const w = canvas.width, h = canvas.height;
    ctx.fillStyle = "#f4f4f2";
    ctx.fillRect(0, 0, w, h);
    if (!scene) return;
    if (followBox.checked) follow();
    const b = basis();
    drawGrid(b);
    const f = focal();
    const byConfidence = colourSelect.value === "confidence";
    const items = [];
    drawnPoints = [];
    scene.motions.forEach((m, i) => {
      if (hidden[i] || m.frame_count === 0) return;
      const frame = frameOf(m, clock.t);
      const cam = [];
      for (let p = 0; p < m.names.length; p++) cam.push(toCamera(b, pointPosition(m, i, frame, p)));
      for (let p = 0; p < m.names.length; p++) {
        const conf = pointConfidence(m, frame, p);
        const colour = byConfidence && conf !== null ? confidenceColour(conf) : m.colour;
        const parent = m.parents[p];
        if (parent !== null && m.bones[p]) {
          const seg = clipNear(cam[parent], cam[p]);
          if (seg) items.push({ depth: (seg[0][2] + seg[1][2]) / 2, kind: "bone", a: seg[0], c: seg[1], colour });
        }
        if (m.shown[p] && cam[p][2] >= NEAR) {
          const s = project(cam[p]);
          const endSite = p >= m.joint_count;
          items.push({ depth: cam[p][2] - 1e-3, kind: "joint", s, z: cam[p][2], colour, endSite, motion: i, point: p });
          if (!endSite) drawnPoints.push({ x: s[0], y: s[1], z: cam[p][2], motion: i, point: p, frame });
        }
      }
    });
    items.sort((p, q) => q.depth - p.depth);
    for (const it of items) {
      if (it.kind === "bone") {
        const a = project(it.a), c = project(it.c);
        const width = clamp(0.022 * f / ((it.a[2] + it.c[2]) / 2), 1.5, 9);
        ctx.strokeStyle = it.colour;
        ctx.lineWidth = width;
        ctx.lineCap = "round";
        ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(c[0], c[1]); ctx.stroke();
      } else if (!it.endSite) {
        const r = clamp(0.022 * f / it.z, 2, 10);
        ctx.fillStyle = "#fff";
        ctx.beginPath(); ctx.arc(it.s[0], it.s[1], r, 0, 2 * Math.PI); ctx.fill();
        ctx.strokeStyle = it.colour;
        ctx.lineWidth = Math.max(1.5, r * 0.45);
        ctx.stroke();
        if (hover && hover.motion === it.motion && hover.point === it.point) {
          ctx.strokeStyle = "#000";
          ctx.lineWidth = 2;
          ctx.beginPath(); ctx.arc(it.s[0], it.s[1], r + 4, 0, 2 * Math.PI); ctx.stroke();
        }
      }
    }
    updateFrameLabel();
  }

  function updateFrameLabel() {
    const first = scene.motions.findIndex((m, i) => !hidden[i]);
    const m = scene.motions[first >= 0 ? first : 0];
    const text = m
      ? "frame " + frameOf(m, clock.t) + " · " + m.frame_count + " frames · " + clock.t.toFixed(2) + " s"
      : "";
    if (frameLabel.textContent !== text) frameLabel.textContent = text;
  }

  // ---------- controls ----------

  function buildLegend() {
    const list = el("motions");
    scene.motions.forEach((m, i) => {
      const row = document.createElement("label");
      row.className = "motion";
      const box = document.createElement("input");
      box.type = "checkbox";
      box.checked = true;
      box.addEventListener("change", () => { hidden[i] = !box.checked; });
      const swatch = document.createElement("span");
      swatch.className = "swatch";
      swatch.style.background = m.colour;
      const text = document.createElement("span");
      text.textContent = m.label;
      const details = document.createElement("span");
      details.className = "details";
      details.textContent = m.frame_count + " frames, " + String(Math.round(100 / m.frame_time) / 100) +
        " fps, " + m.joint_count + " joints" + (m.confidence ? ", confidence" : "");
      row.title = m.source || m.label;
      row.append(box, swatch, text, details);
      list.append(row);
    });
  }

  function bindControls() {
    playButton.addEventListener("click", () => setPlaying(!clock.playing));
    scrubber.addEventListener("input", () => { setTime(Number(scrubber.value) * clock.step); });
    layoutSelect.addEventListener("change", () => { updateLayout(); fitCamera(); });
    colourSelect.addEventListener("change", () => {
      el("confidence-scale").style.display = colourSelect.value === "confidence" ? "block" : "none";
    });
    el("confidence-scale").style.display = colourSelect.value === "confidence" ? "block" : "none";
    window.addEventListener("resize", resize);
    window.addEventListener("keydown", (e) => {
      if (e.target.tagName === "INPUT" && e.target.type === "range" && e.key !== " ") return;
      if (e.key === " ") { e.preventDefault(); setPlaying(!clock.playing); }
      else if (e.key === "ArrowRight") { setPlaying(false); setTime(clock.t + clock.step); }
      else if (e.key === "ArrowLeft") { setPlaying(false); setTime(clock.t - clock.step); }
    });

    let drag = null;
    canvas.addEventListener("contextmenu", (e) => e.preventDefault());
    canvas.addEventListener("pointerdown", (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      canvas.setPointerCapture(e.pointerId);
      canvas.classList.add("dragging");
    });
    canvas.addEventListener("pointerup", (e) => {
      drag = null;
      canvas.releasePointerCapture(e.pointerId);
      canvas.classList.remove("dragging");
    });
    canvas.addEventListener("pointermove", (e) => {
      if (drag) {
        const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
        drag.x = e.clientX; drag.y = e.clientY;
        if (drag.pan) {
          const b = basis();
          const s = camera.distance / focal() * devicePixelRatio;
          for (let k = 0; k < 3; k++) camera.target[k] += (-dx * b.r[k] + dy * b.u[k]) * s;
        } else {
          camera.yaw -= dx * 0.008;
          camera.pitch = clamp(camera.pitch + dy * 0.008, -1.45, 1.45);
        }
        tooltip.style.display = "none";
        return;
      }
      updateHover(e);
    });
    canvas.addEventListener("pointerleave", () => { hover = null; tooltip.style.display = "none"; });
    canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      camera.distance = clamp(camera.distance * Math.exp(e.deltaY * 0.001), 0.2, 500);
    }, { passive: false });
  }

  function updateHover(e) {
    const rect = canvas.getBoundingClientRect();
    const x = (e.clientX - rect.left) * devicePixelRatio, y = (e.clientY - rect.top) * devicePixelRatio;
    let best = null, bestD = 12 * devicePixelRatio;
    for (const p of drawnPoints) {
      const d = Math.hypot(p.x - x, p.y - y);
      if (d < bestD) { best = p; bestD = d; }
    }
    hover = best;
    if (!best) { tooltip.style.display = "none"; return; }
    const m = scene.motions[best.motion];
    const conf = pointConfidence(m, best.frame, best.point);
    const pos = rawPosition(m, best.frame, best.point);
    tooltip.textContent = m.names[best.point] + "  (" + m.label + ")" +
      (conf !== null ? "\nconfidence " + conf.toFixed(2) : "") +
      "\n" + pos.map((v) => v.toFixed(3)).join(", ") + " m";
    tooltip.style.display = "block";
    tooltip.style.left = (e.clientX + 14) + "px";
    tooltip.style.top = (e.clientY + 14) + "px";
  }

  function resize() {
    const rect = canvas.getBoundingClientRect();
    canvas.width = Math.max(1, Math.round(rect.width * devicePixelRatio));
    canvas.height = Math.max(1, Math.round(rect.height * devicePixelRatio));
  }

  // ---------- small vector helpers ----------

  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function normalize(a) { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; }
  function clamp(v, lo, hi) { return Math.max(lo, Math.min(hi, v)); }

  // ---------- what tests and scripts can ask ----------

  window.mocapViewer = {
    ready: () => scene !== null,
    motionCount: () => (scene ? scene.motions.length : 0),
    frameCounts: () => (scene ? scene.motions.map((m) => m.frame_count) : []),
    jointCounts: () => (scene ? scene.motions.map((m) => m.joint_count) : []),
    labels: () => (scene ? scene.motions.map((m) => m.label) : []),
    colours: () => (scene ? scene.motions.map((m) => m.colour) : []),
    hasConfidence: () => (scene ? scene.motions.map((m) => m.confidence !== null) : []),
    currentFrames: () => (scene ? scene.motions.map((m) => frameOf(m, clock.t)) : []),
    time: () => clock.t,
    playing: () => clock.playing,
    drawnWhilePlaying: () => frameTicks,
    pointName: (motion, point) => scene.motions[motion].names[point],
    bodyRoot: (motion) => rootPoint(scene.motions[motion]),
    // Screen position (canvas pixels) of a joint in the last drawn frame.
    jointOnScreen: (motion, point) => drawnPoints.find((p) => p.motion === motion && p.point === point) || null,
  };
})();
