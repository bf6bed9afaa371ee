// discsim viewer: replays runs exactly from their event logs (inlined into every view.html by discsim/view.py).
//
// Each disc has a list of state records (time, x, y, vx, vy): where the replay starts, then after each of its
// events. Between records a disc flies straight, so its position at time t is that of its last record at or
// before t plus velocity times the time since, wrapped into a periodic box: the same operations, in the same
// order, as discsim.trajectory.reconstruct, so the page draws the numbers trajectory() gives. Under gravity
// (g) a record whose disc falls after it (falls[k]: not at rest, not an obstacle) gives x + (v + g dt / 2) dt,
// discsim.physics.dynamics.advance's arithmetic. Where the run says how its discs turn, each record also holds
// the disc's spin and angle (turning[2k], turning[2k + 1]), and a radius line on the disc shows its angle. A disc whose
// state is NaN (before its ADD record, from its REMOVE record on: add_discs / remove_discs) is not drawn.
// Sensors (rows [code, a0, a1, a2, a3]: 1 a circle, 2 a rectangle, 3 a trip wire) are drawn under the discs:
// regions translucent and outlined, a wire dashed with a small arrow to its inside (the left of p1 - p0); a
// sensor lights up for 0.3 s of playing after a disc enters it (the log's ENTER records). Segments (rows [x0, y0,
// x1, y1] at time 0, and [vx, vy] after them for a moving one) are drawn where they are at the time drawn.
"use strict";
(function () {
  const DATA = JSON.parse(document.getElementById("ds-data").textContent);
  const TAB10 = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                 "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
  const OBSTACLE = "#8c8c8c";
  const SENSOR = "#b8860b";  // dark goldenrod: apart from tab10 and viridis
  const SENSOR_SHAPES = { 1: "circle", 2: "rectangle", 3: "line" };
  const PISTON = "#37474f", PISTON_BAR = 6;  // blue grey: the piston's bar (pixels thick) and the box above it
  const FLASH_SECONDS = 0.3;  // of playing (real time): a sensor stays lit this long after a disc enters it
  // viridis at 9 evenly spaced points, interpolated linearly
  const VIRIDIS = [[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
                   [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]];

  function decode(b64, Type) {
    const bin = atob(b64);
    const bytes = new Uint8Array(bin.length);
    for (let k = 0; k < bin.length; k++) bytes[k] = bin.charCodeAt(k);
    return new Type(bytes.buffer);
  }

  // numpy's mod for a positive divisor, then Box.wrap's rule: a result equal to the size becomes 0.
  function wrap(x, size) {
    let m = x % size;
    if (m !== 0 && m < 0) m += size;
    return m >= size ? 0 : m;
  }

  function viridis(f) {
    f = Math.min(1, Math.max(0, f)) * (VIRIDIS.length - 1);
    const k = Math.min(VIRIDIS.length - 2, Math.floor(f));
    const u = f - k;
    const c = VIRIDIS[k].map((a, m) => Math.round(a + (VIRIDIS[k + 1][m] - a) * u));
    return `rgb(${c[0]},${c[1]},${c[2]})`;
  }

  // --- the runs ----------------------------------------------------------------------------------------------
  const runs = DATA.runs.map((r) => {
    const run = {
      label: r.label, engine: r.engine, dt: r.dt, truth: r.truth, n: r.n, box: r.box, segments: r.segments,
      segmentPast: r.segment_past || [],
      radii: decode(r.radii, Float64Array), fixed: decode(r.fixed, Uint8Array),
      groups: decode(r.groups, Int32Array), starts: decode(r.starts, Int32Array),
      times: decode(r.times, Float64Array), states: decode(r.states, Float64Array),
      partners: decode(r.partners, Int32Array), maxSpeed: r.max_speed,
      gravity: r.gravity || null, falls: decode(r.falls, Uint8Array),
      turning: r.turning ? decode(r.turning, Float64Array) : null,
      contactTimes: decode(r.contact_times, Float64Array), contactPairs: decode(r.contact_pairs, Int32Array),
      sensors: r.sensors, enterTimes: decode(r.enter_times, Float64Array),
      enterSensors: decode(r.enter_sensors, Int32Array),
    };
    run.lit = new Uint8Array(run.sensors.length);
    run.drawnSegments = [];
    run.x = new Float64Array(run.n);
    run.y = new Float64Array(run.n);
    run.rec = new Int32Array(run.n);
    run.angle = new Float64Array(run.n);
    run.drawnTime = NaN;
    run.piston = r.piston ? pistonKnots(r.piston) : null;  // a piston's knots, or null: none
    run.pistonHeight = NaN;  // its height last drawn
    return run;
  });
  const T0 = DATA.span[0], T1 = DATA.span[1];

  // The last record of disc d at or before t (as numpy's searchsorted(..., side="right") - 1, at least the first).
  function recordAt(run, d, t) {
    let lo = run.starts[d], hi = run.starts[d + 1];
    const first = lo;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (run.times[mid] <= t) lo = mid + 1; else hi = mid;
    }
    return Math.max(first, lo - 1);
  }

  // The centre t after record k's time (unwrapped): straight, or along the parabola while the disc falls.
  function centre(run, k, t) {
    const s = run.states, dt = t - run.times[k];
    if (run.gravity && run.falls[k]) {
      const gx = run.gravity[0], gy = run.gravity[1];
      return [s[4 * k] + (s[4 * k + 2] + 0.5 * gx * dt) * dt, s[4 * k + 1] + (s[4 * k + 3] + 0.5 * gy * dt) * dt];
    }
    return [s[4 * k] + s[4 * k + 2] * dt, s[4 * k + 1] + s[4 * k + 3] * dt];
  }

  // The velocity at t after record k (it changes by g dt while the disc falls).
  function velocity(run, k, t) {
    const s = run.states;
    if (run.gravity && run.falls[k]) {
      const dt = t - run.times[k];
      return [s[4 * k + 2] + run.gravity[0] * dt, s[4 * k + 3] + run.gravity[1] * dt];
    }
    return [s[4 * k + 2], s[4 * k + 3]];
  }

  // Every disc's position at time t into run.x, run.y (its record into run.rec, its angle into run.angle).
  function evaluate(run, t) {
    const w = run.box.width, h = run.box.height, periodic = run.box.periodic, turning = run.turning;
    for (let d = 0; d < run.n; d++) {
      const k = recordAt(run, d, t);
      let [x, y] = centre(run, k, t);
      if (periodic) { x = wrap(x, w); y = wrap(y, h); }
      run.x[d] = x; run.y[d] = y; run.rec[d] = k;
      if (turning) run.angle[d] = turning[2 * k + 1] + turning[2 * k] * (t - run.times[k]);
    }
  }

  // Which sensors a disc entered in (t - the flash's span of simulated time, t] into run.lit.
  // The entries are in time order: search for the last at or before t, then walk back through the span.
  function light(run, t) {
    run.lit.fill(0);
    const span = FLASH_SECONDS * state.speed, times = run.enterTimes;
    let lo = 0, hi = times.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (times[mid] <= t) lo = mid + 1; else hi = mid;
    }
    for (let e = lo - 1; e >= 0 && t - times[e] <= span; e--) run.lit[run.enterSensors[e]] = 1;
  }

  // An arrow on the canvas from (bx, by) to (ex, ey) (pixels), its head `head` pixels long, in the current colours.
  function drawArrow(ctx, bx, by, ex, ey, head) {
    const len = Math.hypot(ex - bx, ey - by), ux = (ex - bx) / len, uy = (ey - by) / len;
    ctx.beginPath();
    ctx.moveTo(bx, by);
    ctx.lineTo(ex, ey);
    ctx.stroke();
    ctx.beginPath();
    ctx.moveTo(ex, ey);
    ctx.lineTo(ex - head * (ux + 0.5 * uy), ey - head * (uy - 0.5 * ux));
    ctx.lineTo(ex - head * (ux - 0.5 * uy), ey - head * (uy + 0.5 * ux));
    ctx.fill();
  }

  // Each segment's end points at time t into run.drawnSegments ([x0, y0, x1, y1]): a moving one (a row of six:
  // p0, p1, velocity) at p0 + v t, p1 + v t (Segment.at's arithmetic); a fixed one (four) where it is. Before a
  // steer (sim.set_segment_velocity), the motion it had then: run.segmentPast[k], rows [until, p0, p1, velocity].
  function placeSegments(run, t) {
    run.drawnSegments = run.segments.map((row, k) => {
      const past = (run.segmentPast[k] || []).find((p) => t < p[0]);
      const s = past ? past.slice(1) : row;
      if (s.length < 6) return s.slice(0, 4);
      const sx = s[4] * t, sy = s[5] * t;
      return [s[0] + sx, s[1] + sy, s[2] + sx, s[3] + sy];
    });
  }

  // A piston (the box's top wall as a body: discsim.Piston): its knots, the state after each and the acceleration
  // of the piece that follows it (discsim.analysis.piston_path).
  function pistonKnots(p) {
    return { times: decode(p.times, Float64Array), heights: decode(p.heights, Float64Array),
             velocities: decode(p.velocities, Float64Array), accel: decode(p.accel, Float64Array) };
  }

  // The piston's height at t: from its last knot at or before t (the first before it), h + s (u - a s / 2), the
  // arithmetic of PistonPath.state.
  function pistonHeight(piston, t) {
    let lo = 0, hi = piston.times.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (piston.times[mid] <= t) lo = mid + 1; else hi = mid;
    }
    const k = Math.max(0, lo - 1), s = t - piston.times[k];
    return piston.heights[k] + s * (piston.velocities[k] - 0.5 * piston.accel[k] * s);
  }

  // The piston at t: the box above it shaded (no gas there), a thick bar across the box on top of the gas.
  function drawPiston(ctx, run, X, Y, z, t) {
    if (!run.piston) return;
    const h = pistonHeight(run.piston, t), box = run.box;
    run.pistonHeight = h;
    ctx.fillStyle = PISTON;
    ctx.globalAlpha = 0.18;
    ctx.fillRect(X(0), Y(box.height), box.width * z, (box.height - h) * z);
    ctx.globalAlpha = 1;
    ctx.fillRect(X(0), Y(h) - PISTON_BAR, box.width * z, PISTON_BAR);
  }

  function drawSensors(ctx, run, X, Y, z) {
    ctx.strokeStyle = SENSOR;
    ctx.fillStyle = SENSOR;
    for (let k = 0; k < run.sensors.length; k++) {
      const [code, a0, a1, a2, a3] = run.sensors[k], lit = run.lit[k];
      ctx.lineWidth = lit ? 3 : 1.5;
      if (code === 3) {  // a trip wire: dashed (solid while lit), an arrow from its middle to its inside
        ctx.setLineDash(lit ? [] : [6, 4]);
        ctx.beginPath();
        ctx.moveTo(X(a0), Y(a1));
        ctx.lineTo(X(a2), Y(a3));
        ctx.stroke();
        ctx.setLineDash([]);
        const len = Math.hypot(a2 - a0, a3 - a1), nx = -(a3 - a1) / len, ny = (a2 - a0) / len;
        const bx = X((a0 + a2) / 2), by = Y((a1 + a3) / 2), size = 12;  // the canvas's y points down
        ctx.lineWidth = 1.5;
        drawArrow(ctx, bx, by, bx + size * nx, by - size * ny, 5);
        continue;
      }
      ctx.beginPath();
      if (code === 1) ctx.arc(X(a0), Y(a1), Math.max(0.5, a2 * z), 0, 2 * Math.PI);
      else ctx.rect(X(a0), Y(a3), (a2 - a0) * z, (a3 - a1) * z);
      ctx.globalAlpha = lit ? 0.4 : 0.12;
      ctx.fill();
      ctx.globalAlpha = 1;
      ctx.stroke();
    }
  }

  function positionOf(run, d, t) {
    let [x, y] = centre(run, recordAt(run, d, t), t);
    if (run.box.periodic) { x = wrap(x, run.box.width); y = wrap(y, run.box.height); }
    return [x, y];
  }

  // Exact contacts of the truth runs: time, both discs and where they touched.
  const contacts = [];
  for (const run of runs) {
    if (!run.truth) continue;
    for (let c = 0; c < run.contactTimes.length; c++) {
      const t = run.contactTimes[c];
      for (const d of [run.contactPairs[2 * c], run.contactPairs[2 * c + 1]]) {
        const [x, y] = positionOf(run, d, t);
        contacts.push({ t, d, x, y, r: run.radii[d], fixed: run.fixed[d], group: run.groups[d] });
      }
    }
  }
  contacts.sort((a, b) => a.t - b.t);

  // Every event time of every run, sorted, for stepping event by event.
  const eventTimes = (() => {
    const all = [];
    for (const run of runs) for (let k = 0; k < run.times.length; k++) if (run.partners[k] !== -2) all.push(run.times[k]);
    all.sort((a, b) => a - b);
    return all.filter((t, k) => (k === 0 || t !== all[k - 1]) && t >= T0 && t <= T1);
  })();
  const frameStep = Math.max(0, ...runs.map((r) => r.dt || 0));

  // --- state of the player -----------------------------------------------------------------------------------
  const state = {
    t: T0, playing: false, speed: DATA.speed, fps: DATA.fps, colour: DATA.colour,
    contacts: true, numbers: runs[0].n <= 20, loop: false, timer: null, wallStart: 0, tStart: T0,
    arrows: !!DATA.arrows, zoom: 1, focus: [runs[0].box.width / 2, runs[0].box.height / 2],
  };
  // Velocity arrows: an arrow is where the disc gets in this time (the fastest 1% reach about four radii).
  const arrowTime = (() => {
    let r = 0;
    for (const run of runs) for (let d = 0; d < run.n; d++) if (run.radii[d] > r) r = run.radii[d];
    const v = Math.max(...runs.map((run) => run.maxSpeed));
    return v > 0 ? (4 * r) / v : 0;
  })();

  function colourOf(run, d) {
    if (run.fixed[d]) return OBSTACLE;
    if (state.colour === "group") return TAB10[((run.groups[d] % 10) + 10) % 10];
    if (state.colour === "speed") {
      const [vx, vy] = velocity(run, run.rec[d], run.drawnTime);
      return viridis(run.maxSpeed > 0 ? Math.hypot(vx, vy) / run.maxSpeed : 0);
    }
    return TAB10[d % 10];
  }

  function contactColour(c) {
    if (c.fixed) return OBSTACLE;
    if (state.colour === "group") return TAB10[((c.group % 10) + 10) % 10];
    if (state.colour === "speed") return "#222";
    return TAB10[c.d % 10];
  }

  // --- the page ------------------------------------------------------------------------------------------------
  const panelsEl = document.getElementById("ds-panels");
  const panels = runs.map((run) => {
    const div = document.createElement("div");
    div.className = "ds-panel";
    const h2 = document.createElement("h2");
    h2.textContent = run.label + " ";
    const clock = document.createElement("span");  // the time, above the box: never over the discs
    clock.className = "ds-clock";
    h2.append(clock);
    const canvas = document.createElement("canvas");
    div.append(h2, canvas);
    panelsEl.append(div);
    return { run, canvas, clock, ctx: canvas.getContext("2d"), scale: 1, pad: 0, cssWidth: 0, cssHeight: 0 };
  });

  function layout() {
    const ratio = window.devicePixelRatio || 1;
    for (const p of panels) {
      const box = p.run.box;
      const cssWidth = Math.max(120, p.canvas.parentElement.clientWidth - 2);
      const maxHeight = Math.max(160, window.innerHeight * 0.72);
      const pad = 0.02 * Math.max(box.width, box.height);
      const scale = Math.min(cssWidth / (box.width + 2 * pad), maxHeight / (box.height + 2 * pad));
      p.scale = scale; p.pad = pad;
      p.cssWidth = cssWidth;
      p.cssHeight = Math.ceil((box.height + 2 * pad) * scale);
      p.canvas.style.height = p.cssHeight + "px";
      p.canvas.width = Math.round(cssWidth * ratio);
      p.canvas.height = Math.round(p.cssHeight * ratio);
      p.ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    }
  }

  function draw(p, t) {
    const { run, ctx, scale } = p;
    const box = run.box, pad = p.pad;
    // Zoom about state.focus (a point of the box, drawn at the canvas's centre): 1 shows the whole box.
    const z = scale * state.zoom, [fx, fy] = state.focus;
    const X = (x) => p.cssWidth / 2 + (x - fx) * z;
    const Y = (y) => p.cssHeight / 2 - (y - fy) * z;
    void pad;
    ctx.clearRect(0, 0, p.cssWidth, p.cssHeight);
    ctx.save();
    ctx.beginPath();
    ctx.rect(X(0), Y(box.height), box.width * z, box.height * z);
    if (box.periodic) ctx.clip();  // discs crossing a periodic edge show on both sides
    const shifts = box.periodic ? [-1, 0, 1] : [0];
    drawSensors(ctx, run, X, Y, z);
    drawPiston(ctx, run, X, Y, z, t);
    for (let d = 0; d < run.n; d++) {
      const r = run.radii[d];
      if (!Number.isFinite(run.x[d])) continue;  // not there at t (added later, or removed)
      ctx.fillStyle = colourOf(run, d);
      ctx.globalAlpha = 0.8;
      for (const sx of shifts) {
        for (const sy of shifts) {
          const x = run.x[d] + sx * box.width, y = run.y[d] + sy * box.height;
          if (x + r < 0 || x - r > box.width || y + r < 0 || y - r > box.height) continue;
          ctx.beginPath();
          ctx.arc(X(x), Y(y), Math.max(0.5, r * z), 0, 2 * Math.PI);
          ctx.fill();
        }
      }
    }
    ctx.globalAlpha = 1;
    if (run.turning) {  // each disc's angle: a radius from its centre
      ctx.strokeStyle = "#111";
      ctx.lineWidth = 1.2;
      for (let d = 0; d < run.n; d++) {
        const r = run.radii[d], a = run.angle[d];
        if (!Number.isFinite(run.x[d]) || r * z < 3) continue;
        for (const sx of shifts) {
          for (const sy of shifts) {
            const x = run.x[d] + sx * box.width, y = run.y[d] + sy * box.height;
            if (x + r < 0 || x - r > box.width || y + r < 0 || y - r > box.height) continue;
            ctx.beginPath();
            ctx.moveTo(X(x), Y(y));
            ctx.lineTo(X(x + r * Math.cos(a)), Y(y + r * Math.sin(a)));
            ctx.stroke();
          }
        }
      }
    }
    if (state.contacts && contacts.length) {
      const window_ = DATA.contact_window;
      ctx.lineWidth = 1.8;
      ctx.setLineDash(run.truth ? [] : [5, 4]);
      for (const c of contacts) {
        if (c.t > t) break;
        if (window_ !== null && c.t < t - window_) continue;
        ctx.strokeStyle = contactColour(c);
        ctx.beginPath();
        ctx.arc(X(c.x), Y(c.y), Math.max(0.5, c.r * z), 0, 2 * Math.PI);
        ctx.stroke();
      }
      ctx.setLineDash([]);
    }
    if (state.arrows && arrowTime > 0) {
      ctx.strokeStyle = "#111";
      ctx.fillStyle = "#111";
      ctx.lineWidth = 1.2;
      for (let d = 0; d < run.n; d++) {
        const x = run.x[d], y = run.y[d];
        if (!Number.isFinite(x) || run.fixed[d]) continue;
        const [vx, vy] = velocity(run, run.rec[d], t);
        const ex = X(x + vx * arrowTime), ey = Y(y + vy * arrowTime);
        const bx = X(x), by = Y(y), len = Math.hypot(ex - bx, ey - by);
        if (len < 1) continue;
        drawArrow(ctx, bx, by, ex, ey, Math.min(6, 0.4 * len));
      }
    }
    if (state.numbers && run.n <= 50) {
      ctx.fillStyle = "#111";
      ctx.textAlign = "center";
      ctx.textBaseline = "middle";
      for (let d = 0; d < run.n; d++) {
        if (!Number.isFinite(run.x[d])) continue;
        const size = Math.max(9, Math.min(14, run.radii[d] * z * 0.9));
        ctx.font = `${size}px sans-serif`;
        ctx.fillText(String(d), X(run.x[d]), Y(run.y[d]));
      }
    }
    ctx.restore();
    ctx.strokeStyle = "#333";
    ctx.lineWidth = 1.2;
    ctx.setLineDash(box.periodic ? [2, 3] : []);
    ctx.strokeRect(X(0), Y(box.height), box.width * z, box.height * z);
    ctx.setLineDash([]);
    ctx.lineWidth = 2;
    for (const s of run.drawnSegments) {
      ctx.beginPath();
      ctx.moveTo(X(s[0]), Y(s[1]));
      ctx.lineTo(X(s[2]), Y(s[3]));
      ctx.stroke();
    }
    p.clock.textContent = `t = ${t.toFixed(4)}` + (state.zoom !== 1 ? `, zoom ${+state.zoom.toPrecision(3)}x` : "");
  }

  // --- controls ------------------------------------------------------------------------------------------------
  const controls = document.getElementById("ds-controls");
  function el(tag, props, parent = controls) {
    const e = Object.assign(document.createElement(tag), props);
    parent.append(e);
    return e;
  }
  function labelled(text, input) {
    const label = el("label", { textContent: text + " " });
    label.append(input);
    return input;
  }
  el("button", { textContent: "|<", title: "to the start (Home)", onclick: () => seek(T0) });
  el("button", { textContent: "<<", title: "previous event (Shift+Left)", onclick: () => previousEvent() });
  el("button", { textContent: "<", title: "one frame back (Left)", onclick: () => step(-1) });
  const playButton = el("button", { textContent: "Play", title: "play / pause (Space)", onclick: () => toggle() });
  el("button", { textContent: ">", title: "one frame on (Right)", onclick: () => step(1) });
  el("button", { textContent: ">>", title: "next event (Shift+Right)", onclick: () => nextEvent() });
  el("button", { textContent: ">|", title: "to the end (End)", onclick: () => seek(T1) });
  const SCRUB = 100000;
  const scrub = el("input", { type: "range", id: "ds-scrub", min: 0, max: SCRUB, step: 1, value: 0 });
  scrub.oninput = () => seek(T0 + (T1 - T0) * (scrub.value / SCRUB));
  const timeEl = el("span", { id: "ds-time" });
  const timeInput = labelled("go to t =", el("input", { type: "number", step: "any", value: T0 }));
  timeInput.onchange = () => seek(Number(timeInput.value));
  const speedInput = labelled("speed (time/s)", el("input", { type: "number", step: "any", min: 0, value: state.speed }));
  speedInput.onchange = () => setSpeed(Number(speedInput.value));
  const fpsInput = labelled("fps", el("input", { type: "number", step: "any", min: 1, value: state.fps }));
  fpsInput.onchange = () => setFps(Number(fpsInput.value));
  const colourSelect = labelled("colour", el("select", {}));
  for (const mode of ["disc", "group", "speed"]) el("option", { value: mode, textContent: mode }, colourSelect);
  colourSelect.value = state.colour;
  colourSelect.onchange = () => setColour(colourSelect.value);
  const scaleEl = el("span", { id: "ds-scale", title: "speed: 0 (left) to the 99th percentile of the replay (right)" });
  scaleEl.style.background = `linear-gradient(to right, ${[0, 0.25, 0.5, 0.75, 1].map(viridis).join(",")})`;
  const contactsBox = labelled("contacts", el("input", { type: "checkbox", checked: state.contacts }));
  contactsBox.onchange = () => { state.contacts = contactsBox.checked; render(); };
  const numbersBox = labelled("numbers", el("input", { type: "checkbox", checked: state.numbers }));
  numbersBox.onchange = () => { state.numbers = numbersBox.checked; render(); };
  const arrowsBox = labelled("arrows", el("input", { type: "checkbox", checked: state.arrows }));
  arrowsBox.onchange = () => { state.arrows = arrowsBox.checked; render(); };
  const loopBox = labelled("loop", el("input", { type: "checkbox", checked: state.loop }));
  loopBox.onchange = () => { state.loop = loopBox.checked; };

  document.getElementById("ds-info").textContent =
    `${runs[0].n} discs, ${runs[0].box.periodic ? "periodic box" : "box with walls"} ` +
    `${+runs[0].box.width.toPrecision(6)} x ${+runs[0].box.height.toPrecision(6)}; t from ${T0} to ${T1}; ` +
    `${eventTimes.length} event times; ${contacts.length / 2} exact contacts (outlined)` +
    (runs[0].sensors.length ? `; ${runs[0].sensors.length} sensors (gold; lit when a disc enters). ` : ". ") +
    "Keys: Space play/pause, Left/Right one frame, Shift+Left/Right one event. " +
    "Zoom: the mouse wheel (or + and -), drag to move, double-click (or 0) for the whole box.";

  // --- the player ----------------------------------------------------------------------------------------------
  function render() {
    for (const p of panels) {
      evaluate(p.run, state.t);
      light(p.run, state.t);
      placeSegments(p.run, state.t);
      p.run.drawnTime = state.t;
      draw(p, state.t);
    }
    timeEl.textContent = `t = ${state.t.toPrecision(8)} of [${T0}, ${T1}]`;
    if (document.activeElement !== timeInput) timeInput.value = +state.t.toPrecision(10);  // follows playback
    if (document.activeElement !== scrub) scrub.value = T1 > T0 ? Math.round(((state.t - T0) / (T1 - T0)) * SCRUB) : 0;
    colourSelect.value = state.colour;
    scaleEl.style.display = state.colour === "speed" ? "inline-block" : "none";
  }

  function seek(t) {
    if (!Number.isFinite(t)) return state.t;
    state.t = Math.min(T1, Math.max(T0, t));
    if (state.playing) { state.tStart = state.t; state.wallStart = performance.now(); }
    render();
    return state.t;
  }

  function tick() {
    if (!state.playing) return;
    let t = state.tStart + ((performance.now() - state.wallStart) / 1000) * state.speed;
    if (t >= T1) {
      if (state.loop) { state.tStart = T0; state.wallStart = performance.now(); t = T0; } else { t = T1; }
    }
    state.t = t;
    render();
    if (t >= T1 && !state.loop) { pause(); return; }
    state.timer = setTimeout(tick, 1000 / state.fps);
  }

  function play() {
    if (state.playing) return;
    if (state.t >= T1) state.t = T0;
    state.playing = true;
    state.tStart = state.t;
    state.wallStart = performance.now();
    playButton.textContent = "Pause";
    state.timer = setTimeout(tick, 1000 / state.fps);
  }

  function pause() {
    state.playing = false;
    clearTimeout(state.timer);
    playButton.textContent = "Play";
  }

  function toggle() { if (state.playing) pause(); else play(); }

  // One frame: a PIT run's frame interval (to the next frame time), else what one drawn frame covers while playing.
  function step(frames = 1) {
    pause();
    if (frameStep > 0) {
      const x = (state.t - T0) / frameStep;
      const k = Math.abs(x - Math.round(x)) < 1e-9 ? Math.round(x) : frames > 0 ? Math.floor(x) : Math.ceil(x);
      return seek(T0 + (k + frames) * frameStep);
    }
    return seek(state.t + (frames * state.speed) / state.fps);
  }

  function nextEvent() {
    pause();
    const t = eventTimes.find((e) => e > state.t);
    return seek(t === undefined ? T1 : t);
  }

  function previousEvent() {
    pause();
    let t = T0;
    for (const e of eventTimes) { if (e < state.t) t = e; else break; }
    return seek(t);
  }

  function setSpeed(s) {
    if (!(s > 0) || !Number.isFinite(s)) return state.speed;
    state.speed = s;
    speedInput.value = s;
    if (state.playing) { state.tStart = state.t; state.wallStart = performance.now(); }
    return s;
  }

  function setFps(f) {
    if (!(f > 0) || !Number.isFinite(f)) return state.fps;
    state.fps = f;
    fpsInput.value = f;
    return f;
  }

  // Zoom by `factor` (1: the whole box) about the box point (x, y), drawn at the centre; default the focus.
  function setZoom(factor, x = state.focus[0], y = state.focus[1]) {
    if (!(factor > 0) || !Number.isFinite(factor)) return state.zoom;
    state.zoom = Math.min(1000, Math.max(1, factor));
    const box = runs[0].box;
    state.focus = state.zoom === 1 ? [box.width / 2, box.height / 2] : [x, y];
    render();
    return state.zoom;
  }

  function setArrows(on) {
    state.arrows = !!on;
    arrowsBox.checked = state.arrows;
    render();
    return state.arrows;
  }

  // The box point under a mouse event on a panel's canvas.
  function boxPoint(p, e) {
    const rect = p.canvas.getBoundingClientRect(), z = p.scale * state.zoom;
    return [state.focus[0] + (e.clientX - rect.left - p.cssWidth / 2) / z,
            state.focus[1] - (e.clientY - rect.top - p.cssHeight / 2) / z];
  }
  for (const p of panels) {
    p.canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      const [x, y] = boxPoint(p, e), old = state.zoom, factor = Math.min(1000, Math.max(1, old * (e.deltaY < 0 ? 1.25 : 0.8)));
      const keep = old / factor;  // the point under the mouse stays there
      setZoom(factor, x + (state.focus[0] - x) * keep, y + (state.focus[1] - y) * keep);
    }, { passive: false });
    let drag = null;
    p.canvas.addEventListener("mousedown", (e) => { drag = [e.clientX, e.clientY, ...state.focus]; });
    window.addEventListener("mouseup", () => { drag = null; });
    window.addEventListener("mousemove", (e) => {
      if (!drag || state.zoom === 1) return;
      const z = p.scale * state.zoom;
      state.focus = [drag[2] - (e.clientX - drag[0]) / z, drag[3] + (e.clientY - drag[1]) / z];
      render();
    });
    p.canvas.addEventListener("dblclick", () => setZoom(1));
  }

  function setColour(mode) {
    if (["disc", "group", "speed"].includes(mode)) state.colour = mode;
    render();
    return state.colour;
  }

  // The centres last drawn on a panel, [[x, y], ...] (what the canvas shows).
  function positions(panel = 0) {
    const run = panels[panel].run;
    return Array.from({ length: run.n }, (_, d) => [run.x[d], run.y[d]]);
  }

  // The angles of the marks last drawn on a panel, [a, ...] (null: the run does not say how its discs turn).
  function angles(panel = 0) {
    const run = panels[panel].run;
    return run.turning ? Array.from(run.angle) : null;
  }

  // The sensors last drawn on a panel: [{shape, params: [a0, a1, a2, a3], lit}, ...] (lit: a disc entered it
  // within the flash's span before the time drawn).
  function sensors(panel = 0) {
    const run = panels[panel].run;
    return run.sensors.map((row, k) => ({ shape: SENSOR_SHAPES[row[0]], params: row.slice(1), lit: !!run.lit[k] }));
  }

  // The segments last drawn on a panel: [[x0, y0, x1, y1], ...] (a moving one where it was at the time drawn).
  function segments(panel = 0) {
    return panels[panel].run.drawnSegments.map((s) => s.slice());
  }

  // The piston last drawn on a panel: {time, height}, or null without one.
  function piston(panel = 0) {
    const run = panels[panel].run;
    return run.piston ? { time: run.drawnTime, height: run.pistonHeight } : null;
  }

  // Writes {time, positions: [panel][disc][x, y]} into <pre id="ds-readout"> for tools that read the DOM.
  function readout() {
    const out = { time: state.t, drawn: panels.map((p) => p.run.drawnTime), positions: panels.map((_, k) => positions(k)) };
    const text = JSON.stringify(out);
    document.getElementById("ds-readout").textContent = text;
    return text;
  }

  document.addEventListener("keydown", (e) => {
    if (e.target && ["INPUT", "SELECT"].includes(e.target.tagName) && e.target.type !== "range") return;
    if (e.key === " ") { toggle(); e.preventDefault(); }
    else if (e.key === "ArrowRight") { if (e.shiftKey) nextEvent(); else step(1); e.preventDefault(); }
    else if (e.key === "ArrowLeft") { if (e.shiftKey) previousEvent(); else step(-1); e.preventDefault(); }
    else if (e.key === "Home") seek(T0);
    else if (e.key === "End") seek(T1);
    else if (e.key === "+" || e.key === "=") setZoom(state.zoom * 1.25);
    else if (e.key === "-") setZoom(state.zoom * 0.8);
    else if (e.key === "0") setZoom(1);
  });
  window.addEventListener("resize", () => { layout(); render(); });

  window.discsim = {
    seek, time: () => state.t, positions, angles, sensors, segments, piston, play, pause, step, nextEvent, previousEvent, setSpeed, setFps,
    setColour, setZoom, setArrows, zoom: () => state.zoom, readout, span: [T0, T1], panels: panels.length, playing: () => state.playing,
    labels: runs.map((r) => r.label), eventTimes: () => eventTimes.slice(),
  };

  layout();
  const fromHash = /(?:^#|&)t=([^&]+)/.exec(window.location.hash);
  state.t = fromHash && Number.isFinite(Number(fromHash[1])) ? Math.min(T1, Math.max(T0, Number(fromHash[1]))) : T0;
  render();
})();
