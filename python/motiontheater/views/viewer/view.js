/* motiontheater viewer: a skeleton player, joint tree, curves and an editor in one offline page.
 *
 * The page holds each take's channel values (exactly, see decodeValues) and its joint tree, and
 * computes forward kinematics here, as mtcore's C kernel does: the channels are needed anyway for
 * the joint table, the curves and the editing preview, and positions would add three numbers per
 * joint per frame to the file.  The editing steps are ports of motiontheater.editing.interpolators and
 * motiontheater.editing.filtering (and of the mtcore rotation kernels they call), so that a recipe written
 * here and applied by motiontheater gives the motion previewed here.
 *
 * Positions stay in the take's own axes (as motiontheater computes them); only the drawing turns
 * them, by the take's "turn" that stands its up axis along +y (see placed).  The joints that stand
 * still above the take's body (a game rig's static root) are not drawn, nor their bones, and the
 * camera follows the body.
 */
"use strict";
(function () {
  const DATA = JSON.parse(document.getElementById("mt-data").textContent);
  const $ = (id) => document.getElementById(id);
  const COLOURS = ["#1f4e9c", "#c0392b", "#2e8b57", "#8e44ad", "#b8860b", "#0e7c86"];
  const AXIS_COLOURS = { x: "#d62728", y: "#2ca02c", z: "#1f77b4", l: "#7f7f7f" };
  const EPS = 2.220446049250313e-16;

  function fail(message) {
    const box = $("error");
    box.textContent = message;
    box.hidden = false;
  }
  window.addEventListener("error", (e) => fail("viewer error: " + e.message));

  /* ---------- decoding ---------- */

  // 10^d exactly for d = 0..22 (every one is a double): products of exact values, no pow() rounding
  const POW10 = [1];
  for (let d = 1; d <= 22; d++) POW10.push(POW10[d - 1] * 10);

  function bytesOf(b64) {
    const bin = atob(b64);
    const out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out;
  }

  async function inflate(b64) {
    if (typeof DecompressionStream === "undefined") {
      throw new Error("this browser lacks DecompressionStream (Chrome 80, Firefox 113, Safari 16.4 or later)");
    }
    const stream = new Blob([bytesOf(b64)]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  /* Values arrive channel by channel as 32-bit words in four byte planes (low byte first): a word
   * holds m * 32 + d for the value m / 10^d, which division reproduces bit for bit (the quotient of
   * two exact doubles is correctly rounded, as parsing the decimal was); d = 31 takes the next
   * exact float64 of the exceptions.  Returns values (frames x channels, row-major). */
  function decodeValues(planes, frames, channels, exceptions) {
    const n = frames * channels;
    const out = new Float64Array(n);
    let e = 0;
    for (let c = 0, i = 0; c < channels; c++) {
      for (let f = 0; f < frames; f++, i++) {
        const x = planes[i] | (planes[n + i] << 8) | (planes[2 * n + i] << 16) | (planes[3 * n + i] << 24);
        const d = x & 31;
        out[f * channels + c] = d === 31 ? exceptions[e++] : (x >> 5) / POW10[d];
      }
    }
    return out;
  }

  async function loadTake(t, index) {
    const planes = await inflate(t.values.data);
    const exBytes = bytesOf(t.values.exceptions);
    const exceptions = new Float64Array(exBytes.buffer, 0, exBytes.length / 8);
    const J = t.joints.length;
    const take = Object.assign({}, t, {
      index,
      colour: COLOURS[index % COLOURS.length],
      channelCount: t.channels.length,
      values: decodeValues(planes, t.frames, t.channels.length, exceptions),
      axis: Float64Array.from(t.axis),
      segment: Float64Array.from(t.segment),
      direction: Float64Array.from(t.direction),
      parent: Int32Array.from(t.parent),
      order: Int32Array.from(t.order),
      dofStart: Int32Array.from(t.dofStart),
      dofKind: Int32Array.from(t.dofKind),
      dofColumn: Int32Array.from(t.dofColumn),
      parentFrame: Uint8Array.from(t.parentFrame),
      turn: Float64Array.from(t.turn),
      still: new Uint8Array(J),
      plain: new Uint8Array(J),
      jointIndex: new Map(t.joints.map((name, i) => [name, i])),
      plantRows: [],
    });
    for (let j = 0; j < J; j++) {
      let identity = true;
      for (let e = 0; e < 9; e++) if (take.axis[9 * j + e] !== (e % 4 === 0 ? 1 : 0)) identity = false;
      take.plain[j] = identity ? 1 : 0;
    }
    for (const j of t.still) take.still[j] = 1;
    take.bones = []; // [parent, joint]: every bone but those from a joint that stands still above the body
    for (let j = 0; j < J; j++) if (take.parent[j] >= 0 && !take.still[take.parent[j]]) take.bones.push([take.parent[j], j]);
    for (const { label, point, spans } of t.plants || []) {
      const flags = new Uint8Array(t.frames);
      for (const [a, b] of spans) flags.fill(1, a, b + 1);
      take.plantRows.push({ label, j: point, flags });
    }
    take.positions = allPositions(take, take.values);
    return take;
  }

  /* ---------- rotations (ports of csrc/rotation.c) ---------- */

  /* m = R(axis, angle) m, m a row-major 3x3 at offset o */
  function rotateLeft(m, o, axis, s, c) {
    const a = axis === 0 ? 1 : axis === 1 ? 2 : 0;
    const b = axis === 0 ? 2 : axis === 1 ? 0 : 1;
    for (let k = 0; k < 3; k++) {
      const ra = m[o + 3 * a + k], rb = m[o + 3 * b + k];
      m[o + 3 * a + k] = c * ra - s * rb;
      m[o + 3 * b + k] = s * ra + c * rb;
    }
  }

  function setIdentity(m, o) {
    for (let e = 0; e < 9; e++) m[o + e] = e % 4 === 0 ? 1 : 0;
  }

  function eulerToMatrix(angles, axes, intrinsic, scale) {
    const r = new Float64Array(9);
    setIdentity(r, 0);
    for (let step = 0; step < 3; step++) {
      const a = intrinsic ? 2 - step : step;
      const v = angles[a] * scale;
      rotateLeft(r, 0, axes[a], Math.sin(v), Math.cos(v));
    }
    return r;
  }

  function matrixToQuaternion(m, o = 0) {
    const m0 = m[o], m1 = m[o + 1], m2 = m[o + 2], m3 = m[o + 3], m4 = m[o + 4];
    const m5 = m[o + 5], m6 = m[o + 6], m7 = m[o + 7], m8 = m[o + 8];
    const trace = m0 + m4 + m8;
    let w, x, y, z, s;
    if (trace > 0) {
      s = 2 * Math.sqrt(trace + 1);
      w = s / 4; x = (m7 - m5) / s; y = (m2 - m6) / s; z = (m3 - m1) / s;
    } else if (m0 > m4 && m0 > m8) {
      s = 2 * Math.sqrt(1 + m0 - m4 - m8);
      w = (m7 - m5) / s; x = s / 4; y = (m1 + m3) / s; z = (m2 + m6) / s;
    } else if (m4 > m8) {
      s = 2 * Math.sqrt(1 + m4 - m0 - m8);
      w = (m2 - m6) / s; x = (m1 + m3) / s; y = s / 4; z = (m5 + m7) / s;
    } else {
      s = 2 * Math.sqrt(1 + m8 - m0 - m4);
      w = (m3 - m1) / s; x = (m2 + m6) / s; y = (m5 + m7) / s; z = s / 4;
    }
    const sign = w < 0 ? -1 : 1;
    return [sign * w, sign * x, sign * y, sign * z];
  }

  function quaternionToMatrix(q) {
    const [w, x, y, z] = q;
    const s = 2 / (w * w + x * x + y * y + z * z);
    return [
      1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y),
      s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x),
      s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y),
    ];
  }

  const GIMBAL_LOCK = 16 * EPS;

  function matrixToEuler(m, axes, intrinsic, scale) {
    const i = axes[0], j = axes[1], k = 3 - i - j, proper = axes[2] === i;
    const e = (j - i + 3) % 3 === 1 ? 1 : -1;
    const s = intrinsic ? -1 : 1;
    const o = proper ? k : i, f = proper ? e : -e;
    const r = (u, v) => (intrinsic ? m[3 * v + u] : m[3 * u + v]);
    let b, y, x;
    if (proper) {
      b = s * Math.atan2(Math.hypot(r(i, j), r(i, k)), r(i, i));
      y = s * r(j, i);
      x = -s * e * r(k, i);
    } else {
      b = Math.atan2(-e * r(k, i), Math.hypot(r(k, j), r(k, k)));
      y = e * r(j, i);
      x = r(i, i);
    }
    const h = Math.hypot(x, y);
    const lock = h <= GIMBAL_LOCK;
    const cc = lock ? 1 : x / h, sc = lock ? 0 : y / h;
    const a = Math.atan2(-e * (cc * r(j, k) + f * sc * r(o, k)), cc * r(j, j) + f * sc * r(o, j));
    return [(s * a) / scale, (s * b) / scale, lock ? 0 : (s * Math.atan2(y, x)) / scale];
  }

  function halfSinc(x) {
    return x < 1e-4 ? 0.5 - (x * x) / 48 : Math.sin(x / 2) / x;
  }

  function expMap(v) {
    const angle = Math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), k = halfSinc(angle);
    return [Math.cos(angle / 2), k * v[0], k * v[1], k * v[2]];
  }

  function rotvecToQuaternion(v) {
    const q = expMap(v);
    const sign = q[0] < 0 ? -1 : 1;
    return q.map((c) => c * sign);
  }

  function quaternionToRotvec(q) {
    const xyz = Math.sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    const norm = Math.sqrt(q[0] * q[0] + xyz * xyz);
    const h = Math.atan2(xyz, Math.abs(q[0]));
    const k = h < 1e-4 ? (2 * (1 + (h * h) / 6)) / norm : (2 * h) / xyz;
    const sign = q[0] < 0 ? -1 : 1;
    return [sign * k * q[1], sign * k * q[2], sign * k * q[3]];
  }

  function sinRatio(x, theta) {
    return theta < 1e-5 ? x * (1 + ((1 - x * x) * theta * theta) / 6) : Math.sin(x * theta) / Math.sin(theta);
  }

  function slerp(q0, q1, t) {
    const n0 = Math.sqrt(q0[0] * q0[0] + q0[1] * q0[1] + q0[2] * q0[2] + q0[3] * q0[3]);
    const n1 = Math.sqrt(q1[0] * q1[0] + q1[1] * q1[1] + q1[2] * q1[2] + q1[3] * q1[3]);
    const dot = q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3];
    const s1 = dot < 0 ? -1 / n1 : 1 / n1;
    const a = [], b = [];
    let diff = 0, sum = 0;
    for (let c = 0; c < 4; c++) {
      a.push(q0[c] / n0);
      b.push(s1 * q1[c]);
      diff += (a[c] - b[c]) * (a[c] - b[c]);
      sum += (a[c] + b[c]) * (a[c] + b[c]);
    }
    const theta = 2 * Math.atan2(Math.sqrt(diff), Math.sqrt(sum));
    const ka = sinRatio(1 - t, theta), kb = sinRatio(t, theta);
    return [0, 1, 2, 3].map((c) => ka * a[c] + kb * b[c]);
  }

  function interpolateRotvec(v0, v1, t, aligned) {
    let start = v0.slice();
    if (aligned) {
      const q0 = expMap(v0), q1 = expMap(v1);
      if (q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3] < 0) {
        const a0 = Math.sqrt(v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]);
        const a1 = Math.sqrt(v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2]);
        start = [0, 1, 2].map((c) => (a0 > 0 ? v0[c] * (1 - (2 * Math.PI) / a0) : v1[c] * ((2 * Math.PI) / a1)));
      }
    }
    return [0, 1, 2].map((c) => start[c] + t * (v1[c] - start[c]));
  }

  /* round half to even, as C's nearbyint and numpy's round */
  function roundEven(x) {
    const r = Math.round(x);
    return Math.abs(x % 1) === 0.5 && r % 2 !== 0 ? r - 1 : r;
  }

  function nearestTurn(x, ref, turn) {
    return x + turn * roundEven((ref - x) / turn);
  }

  /* of the Euler triples of the rotation cur, the one nearest prev (mt_unroll_euler's step) */
  function unrollStep(prev, cur, proper, halfTurn) {
    const turn = 2 * halfTurn, flip = proper ? 0 : halfTurn;
    const a = [nearestTurn(cur[0], prev[0], turn), nearestTurn(cur[1], prev[1], turn), nearestTurn(cur[2], prev[2], turn)];
    const b = [
      nearestTurn(cur[0] + halfTurn, prev[0], turn),
      nearestTurn(flip - cur[1], prev[1], turn),
      nearestTurn(cur[2] + halfTurn, prev[2], turn),
    ];
    let da = 0, db = 0;
    for (let c = 0; c < 3; c++) {
      da += (a[c] - prev[c]) * (a[c] - prev[c]);
      db += (b[c] - prev[c]) * (b[c] - prev[c]);
    }
    if (Number.isNaN(da)) return cur.slice();
    return db < da ? b : a;
  }

  /* ---------- forward kinematics (port of csrc/kinematics.c) ---------- */

  // scratch of fkFrame (one call at a time: the page is single-threaded)
  const FK_M = new Float64Array(9), FK_L = new Float64Array(9), FK_CM = new Float64Array(9);

  function fkFrame(take, values, row, pos, po, world, local) {
    const J = take.joints.length, scale = take.angleScale;
    const m = FK_M, l = FK_L, cm = FK_CM;
    for (let ii = 0; ii < J; ii++) {
      const j = take.order[ii];
      setIdentity(m, 0);
      let t0 = 0, t1 = 0, t2 = 0, stretch = 0;
      for (let c = take.dofStart[j]; c < take.dofStart[j + 1]; c++) {
        const v = values[row + take.dofColumn[c]], kind = take.dofKind[c];
        if (kind <= 2) {
          const a = v * scale;
          rotateLeft(m, 0, kind, Math.sin(a), Math.cos(a));
        } else if (kind === 3) t0 += v;
        else if (kind === 4) t1 += v;
        else if (kind === 5) t2 += v;
        else stretch += v;
      }
      const C = take.axis, c9 = 9 * j;
      if (take.plain[j]) l.set(m);
      else {
        for (let i = 0; i < 3; i++)
          for (let k = 0; k < 3; k++)
            cm[3 * i + k] = C[c9 + 3 * i] * m[k] + C[c9 + 3 * i + 1] * m[3 + k] + C[c9 + 3 * i + 2] * m[6 + k];
        for (let i = 0; i < 3; i++)
          for (let k = 0; k < 3; k++)
            l[3 * i + k] = cm[3 * i] * C[c9 + 3 * k] + cm[3 * i + 1] * C[c9 + 3 * k + 1] + cm[3 * i + 2] * C[c9 + 3 * k + 2];
      }
      if (local) local.set(l, 9 * j);
      const w = 9 * j, p = take.parent[j], seg = 3 * j;
      if (p < 0) {
        world.set(l, w);
        pos[po + 3 * j] = take.segment[seg] + t0;
        pos[po + 3 * j + 1] = take.segment[seg + 1] + t1;
        pos[po + 3 * j + 2] = take.segment[seg + 2] + t2;
        continue;
      }
      const q = 9 * p;
      for (let i = 0; i < 3; i++)
        for (let k = 0; k < 3; k++)
          world[w + 3 * i + k] = world[q + 3 * i] * l[k] + world[q + 3 * i + 1] * l[3 + k] + world[q + 3 * i + 2] * l[6 + k];
      const S3 = take.segment, D3 = take.direction;
      const v0 = S3[seg] + D3[seg] * stretch + C[c9] * t0 + C[c9 + 1] * t1 + C[c9 + 2] * t2;
      const v1 = S3[seg + 1] + D3[seg + 1] * stretch + C[c9 + 3] * t0 + C[c9 + 4] * t1 + C[c9 + 5] * t2;
      const v2 = S3[seg + 2] + D3[seg + 2] * stretch + C[c9 + 6] * t0 + C[c9 + 7] * t1 + C[c9 + 8] * t2;
      const turn = take.parentFrame[j] ? q : w;
      for (let e = 0; e < 3; e++)
        pos[po + 3 * j + e] = pos[po + 3 * p + e] + world[turn + 3 * e] * v0 + world[turn + 3 * e + 1] * v1 + world[turn + 3 * e + 2] * v2;
    }
  }

  function allPositions(take, values) {
    const J = take.joints.length, C = take.channelCount;
    const pos = new Float64Array(take.frames * J * 3), world = new Float64Array(J * 9);
    for (let f = 0; f < take.frames; f++) fkFrame(take, values, f * C, pos, f * J * 3, world, null);
    return pos;
  }

  /* ---------- editing steps (ports of motiontheater.editing.interpolators and .filtering) ---------- */

  const ROTATIONS = ["rx", "ry", "rz"];

  function columnsOf(take, joint) {
    const start = take.firstColumn[take.jointIndex.get(joint)];
    return take.dofs[take.jointIndex.get(joint)].map((_, i) => start + i);
  }

  function chosenJoints(take, joints) {
    return joints === null ? take.joints : joints;
  }

  function interpolate(take, values, a, b, kind, joints) {
    const C = take.channelCount, out = values.slice();
    const degrees = take.angleUnit === "deg";
    const scale = degrees ? Math.PI / 180 : 1, halfTurn = degrees ? 180 : Math.PI;
    for (const joint of chosenJoints(take, joints)) {
      const dofs = take.dofs[take.jointIndex.get(joint)], cols = columnsOf(take, joint);
      const rotCols = cols.filter((_, i) => ROTATIONS.includes(dofs[i]));
      const rotDofs = dofs.filter((d) => ROTATIONS.includes(d));
      const three = rotDofs.length === 3 && kind !== "euler";
      for (const c of cols) {
        if (three && rotCols.includes(c)) continue;
        const va = values[a * C + c], vb = values[b * C + c];
        for (let f = a + 1; f < b; f++) out[f * C + c] = va + ((f - a) / (b - a)) * (vb - va);
      }
      if (!three) continue;
      const axes = rotDofs.map((d) => "xyz".indexOf(d[1]));
      const intrinsic = take.convention === "bvh";
      const key = (f) => matrixToQuaternion(eulerToMatrix(rotCols.map((c) => values[f * C + c]), axes, intrinsic, scale));
      const k0 = key(a), k1 = key(b);
      let v0, v1;
      if (kind !== "slerp") {
        v0 = quaternionToRotvec(k0);
        v1 = quaternionToRotvec(k1);
      }
      const proper = axes[0] === axes[2];
      let prev = rotCols.map((c) => values[a * C + c]);
      for (let f = a + 1; f < b; f++) {
        const t = (f - a) / (b - a);
        const q = kind === "slerp" ? slerp(k0, k1, t) : rotvecToQuaternion(interpolateRotvec(v0, v1, t, kind === "aligned_expmap"));
        const angles = matrixToEuler(quaternionToMatrix(q), axes, intrinsic, scale);
        prev = unrollStep(prev, angles, proper, halfTurn);
        rotCols.forEach((c, i) => (out[f * C + c] = prev[i]));
      }
    }
    return out;
  }

  function median(window) {
    for (const v of window) if (Number.isNaN(v)) return NaN;
    window.sort((x, y) => x - y);
    return window[(window.length - 1) >> 1];
  }

  /* one column's rows a..b filtered with edges held ("nearest"), into out.  The mean is mtcore's
   * running sum, restarted every max(size, 256) frames and summed again over the window where a
   * NaN or inf leaves it, as its kernel does: a bad sample spoils only the windows that hold it. */
  function filterColumn(src, out, C, c, a, b, kind, size, base) {
    const half = size >> 1, n = b - a + 1;
    const at = (i) => src[(a + Math.min(Math.max(i, 0), n - 1)) * C + c] - base;
    if (kind === "mean") {
      const chunk = Math.max(size, 256);
      for (let t0 = 0; t0 < n; t0 += chunk) {
        let acc = 0;
        for (let j = 0; j + 1 < size; j++) acc += at(t0 - half + j);
        for (let t = t0; t < Math.min(n, t0 + chunk); t++) {
          const sum = acc + at(t - half + size - 1);
          out[(a + t) * C + c] = sum / size + base;
          const leave = at(t - half);
          acc = sum - leave;
          if (!Number.isFinite(leave)) {
            acc = 0;
            for (let j = 1; j < size && !Number.isNaN(acc); j++) acc += at(t - half + j);
          }
        }
      }
      return;
    }
    const weights = kind === "binomial" ? pascal(size) : null;
    for (let i = 0; i < n; i++) {
      let v;
      if (kind === "median") {
        const w = [];
        for (let k = -half; k <= half; k++) w.push(at(i + k));
        v = median(w) + base;
      } else {
        let sum = 0;
        for (let k = -half; k <= half; k++) sum += weights[k + half] * at(i + k);
        v = sum + base;
      }
      out[(a + i) * C + c] = v;
    }
  }

  function pascal(size) {
    const row = [1];
    for (let i = 1; i < size; i++) {
      for (let k = row.length - 1; k > 0; k--) row[k] += row[k - 1];
      row.push(1);
    }
    const total = 2 ** (size - 1);
    return row.map((x) => x / total);
  }

  function median3(take, values, a, b, joints) {
    const C = take.channelCount, out = values.slice();
    for (const joint of chosenJoints(take, joints))
      for (const c of columnsOf(take, joint)) filterColumn(values, out, C, c, a, b, "median", 3, 0);
    return out;
  }

  /* filter_motion over rows a..b as a motion of its own: rotations unwrapped (a sample that is not
   * finite is stepped over), smoothed relative to the first finite value (means), wrapped back into
   * the range the finite samples used (inf and NaN kept as they are) */
  function smooth(take, values, a, b, kind, size, joints) {
    const C = take.channelCount, out = values.slice();
    const period = take.angleUnit === "deg" ? 360 : 2 * Math.PI;
    const rotations = [], others = [];
    for (const joint of chosenJoints(take, joints)) {
      const dofs = take.dofs[take.jointIndex.get(joint)];
      columnsOf(take, joint).forEach((c, i) => (ROTATIONS.includes(dofs[i]) ? rotations : others).push(c));
    }
    const unwrapped = values.slice(); // only rows a..b of the chosen columns are read
    const low = {}, high = {}, base = {};
    for (const c of rotations.concat(others)) {
      let lo = Infinity, hi = -Infinity, first = null;
      for (let f = a; f <= b; f++) {
        const v = values[f * C + c];
        if (!Number.isFinite(v)) continue;
        lo = Math.min(lo, v);
        hi = Math.max(hi, v);
        if (first === null) first = v;
      }
      low[c] = lo;
      high[c] = hi;
      base[c] = first === null ? 0 : first;
    }
    for (const c of rotations) {
      let turns = 0, last = values[a * C + c]; // the last finite sample (the first sample to begin)
      for (let f = a; f <= b; f++) {
        const raw = values[f * C + c], filled = Number.isFinite(raw) ? raw : last;
        const step = filled - last;
        if (Math.abs(step) > period / 2) turns += -roundEven(step / period);
        unwrapped[f * C + c] = raw + turns * period;
        last = filled;
      }
    }
    for (const c of rotations.concat(others)) filterColumn(unwrapped, out, C, c, a, b, kind, size, kind === "median" ? 0 : base[c]);
    const half = period / 2;
    for (const c of rotations) {
      const centred = low[c] >= -half && high[c] <= half;
      const positive = !centred && low[c] >= 0 && high[c] <= period;
      for (let f = a; f <= b; f++) {
        const v = out[f * C + c];
        if (!Number.isFinite(v)) continue;
        if (centred && !(Math.abs(v) <= half)) out[f * C + c] = v - period * Math.floor((v + half) / period);
        if (positive && !(v >= 0 && v <= period)) out[f * C + c] = v - period * Math.floor(v / period);
      }
    }
    return out;
  }

  const INTERPOLATORS = ["euler", "slerp", "expmap", "aligned_expmap"];

  /* a stack entry {kind, first, last (frame numbers), joints (names or null), size} applied to values */
  function applyStep(take, values, step) {
    const a = step.first - take.firstFrame, b = step.last - take.firstFrame;
    if (INTERPOLATORS.includes(step.kind)) return interpolate(take, values, a, b, step.kind, step.joints);
    if (step.kind === "median3") return median3(take, values, a, b, step.joints);
    return smooth(take, values, a, b, step.kind, step.size, step.joints);
  }

  /* ---------- state ---------- */

  const S = {
    takes: [],
    cur: 0,
    time: 0,
    playing: false,
    reverse: false,
    speed: 1,
    loop: true,
    follow: true,
    selected: 0,
    selection: null,
    stack: [],
    preview: true,
    edited: null,
    editedPositions: null,
    dirtyCurves: true,
    dirty: true,
    stats: { ticks: 0, playTicks: 0, drawMs: 0, maxDrawMs: 0 },
  };

  function take0() {
    return S.takes[0];
  }

  function duration(take) {
    return ((take.frames - 1) * take.step) / take.frameRate;
  }

  function indexAt(take, time) {
    return Math.min(take.frames - 1, Math.max(0, Math.round((time * take.frameRate) / take.step)));
  }

  function frameNumber(take, i) {
    return take.firstFrame + i * take.step;
  }

  /* the address says where to open: #frame=N&joint=NAME (a report's link to a finding) */
  function fromAddress() {
    const t = take0();
    const asked = new URLSearchParams(location.hash.slice(1));
    const frame = Number(asked.get("frame"));
    seek(asked.has("frame") && Number.isFinite(frame) ? (frame - t.firstFrame) / t.step : 0);
    const joint = t.jointIndex.get(asked.get("joint"));
    select(joint === undefined ? t.body : joint);
  }

  function seek(i) {
    const t = take0();
    S.cur = Math.min(t.frames - 1, Math.max(0, Math.round(i)));
    S.time = (S.cur * t.step) / t.frameRate;
    S.dirty = true;
  }

  function shownValues(take) {
    return take.index === 0 && S.edited && S.preview ? S.edited : take.values;
  }

  function shownPositions(take) {
    return take.index === 0 && S.edited && S.preview ? S.editedPositions : take.positions;
  }

  /* ---------- 3D view (Canvas 2D, perspective) ---------- */

  const view = $("view3d");
  const ctx = view.getContext("2d");
  const cam = { yaw: 0.7, pitch: 0.28, dist: 1, target: [0, 0, 0], pan: [0, 0, 0], fov: (45 * Math.PI) / 180 };
  let basis = null;

  /* the floor, the camera's distance and the grid, from the first take's drawn joints as drawn */
  function setUpCamera() {
    const t = take0(), P = t.positions, J = t.joints.length;
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    let floor = Infinity;
    for (let f = 0; f < t.frames; f++)
      for (let j = 0; j < J; j++) {
        if (t.still[j]) continue;
        const y = placed(t, P, f * J * 3, j)[1];
        if (Number.isFinite(y)) floor = Math.min(floor, y);
      }
    for (let j = 0; j < J; j++) {
      if (t.still[j]) continue;
      const p = placed(t, P, 0, j);
      for (let e = 0; e < 3; e++) {
        if (Number.isFinite(p[e])) {
          lo[e] = Math.min(lo[e], p[e]);
          hi[e] = Math.max(hi[e], p[e]);
        }
      }
    }
    const height = Math.max(hi[1] - lo[1], hi[0] - lo[0], hi[2] - lo[2], 1e-9);
    S.floor = Number.isFinite(floor) ? floor : 0;
    S.height = height;
    cam.dist = 2.2 * height;
    cam.centreY = (lo[1] + hi[1]) / 2;
    cam.target = [(lo[0] + hi[0]) / 2, cam.centreY, (lo[2] + hi[2]) / 2];
    // the floor grid: lines every 0.5 m over the ground the body covers, and a margin
    let spacing = 0.5 / t.metersPerUnit;
    let x0 = Infinity, x1 = -Infinity, z0 = Infinity, z1 = -Infinity;
    for (let f = 0; f < t.frames; f++) {
      const [x, , z] = placed(t, P, f * J * 3, t.body);
      if (!Number.isFinite(x) || !Number.isFinite(z)) continue;
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); z0 = Math.min(z0, z); z1 = Math.max(z1, z);
    }
    if (!Number.isFinite(x0)) { x0 = x1 = z0 = z1 = 0; }
    const margin = Math.max(height, 2 / t.metersPerUnit);
    while (Math.max(x1 - x0, z1 - z0) + 2 * margin > 120 * spacing) spacing *= 2;
    const snap = (v, up) => (up ? Math.ceil(v / spacing) : Math.floor(v / spacing)) * spacing;
    S.grid = { spacing, x0: snap(x0 - margin, false), x1: snap(x1 + margin, true), z0: snap(z0 - margin, false), z1: snap(z1 + margin, true) };
  }

  function resizeCanvas(canvas) {
    const r = canvas.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(r.width * dpr)), h = Math.max(1, Math.round(r.height * dpr));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
      return true;
    }
    return false;
  }

  function updateBasis() {
    const t = take0(), P = shownPositions(t), J = t.joints.length;
    if (S.follow) {
      const [x, , z] = placed(t, P, S.cur * J * 3, t.body);
      if (Number.isFinite(x) && Number.isFinite(z)) cam.target = [x, cam.centreY, z];
    }
    const tg = [cam.target[0] + cam.pan[0], cam.target[1] + cam.pan[1], cam.target[2] + cam.pan[2]];
    const cp = Math.cos(cam.pitch);
    const eye = [tg[0] + cam.dist * cp * Math.sin(cam.yaw), tg[1] + cam.dist * Math.sin(cam.pitch), tg[2] + cam.dist * cp * Math.cos(cam.yaw)];
    const f = norm([tg[0] - eye[0], tg[1] - eye[1], tg[2] - eye[2]]);
    const r = norm(cross(f, [0, 1, 0]));
    const u = cross(r, f);
    const focal = view.height / 2 / Math.tan(cam.fov / 2);
    basis = { eye, f, r, u, focal, cx: view.width / 2, cy: view.height / 2, near: cam.dist * 0.02 };
  }

  function cross(a, b) {
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  }

  function norm(v) {
    const n = Math.hypot(v[0], v[1], v[2]) || 1;
    return [v[0] / n, v[1] / n, v[2] / n];
  }

  function camSpace(x, y, z) {
    const B = basis, dx = x - B.eye[0], dy = y - B.eye[1], dz = z - B.eye[2];
    return [dx * B.r[0] + dy * B.r[1] + dz * B.r[2], dx * B.u[0] + dy * B.u[1] + dz * B.u[2], dx * B.f[0] + dy * B.f[1] + dz * B.f[2]];
  }

  function toScreen(c) {
    return [basis.cx + (basis.focal * c[0]) / c[2], basis.cy - (basis.focal * c[1]) / c[2]];
  }

  function project(x, y, z) {
    const c = camSpace(x, y, z);
    return c[2] > basis.near && Number.isFinite(c[2]) ? toScreen(c) : null;
  }

  /* a world segment into the path, cut at the near plane */
  function segment(p, q) {
    let a = camSpace(p[0], p[1], p[2]), b = camSpace(q[0], q[1], q[2]);
    const n = basis.near;
    if (!(Number.isFinite(a[2]) && Number.isFinite(b[2])) || (a[2] <= n && b[2] <= n)) return;
    if (a[2] < n || b[2] < n) {
      const s = (n - a[2]) / (b[2] - a[2]);
      const m = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), n];
      if (a[2] < n) a = m;
      else b = m;
    }
    const A = toScreen(a), Bq = toScreen(b);
    ctx.moveTo(A[0], A[1]);
    ctx.lineTo(Bq[0], Bq[1]);
  }

  function drawGrid() {
    const g = S.grid, y = S.floor, dpr = window.devicePixelRatio || 1;
    ctx.lineWidth = dpr;
    for (const major of [false, true]) {
      ctx.beginPath();
      ctx.strokeStyle = major ? "#c8c8c8" : "#e6e6e6";
      for (let x = g.x0, i = Math.round(g.x0 / g.spacing); x <= g.x1 + 1e-9; x += g.spacing, i++)
        if ((i % 2 === 0) === major) segment([x, y, g.z0], [x, y, g.z1]);
      for (let z = g.z0, i = Math.round(g.z0 / g.spacing); z <= g.z1 + 1e-9; z += g.spacing, i++)
        if ((i % 2 === 0) === major) segment([g.x0, y, z], [g.x1, y, z]);
      ctx.stroke();
    }
  }

  /* joint j of the positions P (a frame's from base) as drawn: turned by the take's place (its turn
   * to stand along +y, in the first take's length unit) */
  function placed(take, P, base, j) {
    const M = take.place, x = P[base + 3 * j], y = P[base + 3 * j + 1], z = P[base + 3 * j + 2];
    return [M[0] * x + M[1] * y + M[2] * z, M[3] * x + M[4] * y + M[5] * z, M[6] * x + M[7] * y + M[8] * z];
  }

  /* the canvas pixels of the take's joints at frame i of P: null where one is not drawn (it stands
   * still above the body) or is behind the camera */
  function screenPoints(take, P, i) {
    const J = take.joints.length, base = i * J * 3, out = [];
    for (let j = 0; j < J; j++) out.push(take.still[j] ? null : project(...placed(take, P, base, j)));
    return out;
  }

  function shownIndex(take) {
    return take.index === 0 ? S.cur : indexAt(take, S.time);
  }

  function drawSkeleton(take, P, i, colour, alpha, main) {
    const J = take.joints.length, base = i * J * 3, dpr = window.devicePixelRatio || 1;
    ctx.globalAlpha = alpha;
    ctx.strokeStyle = colour;
    ctx.lineWidth = (main ? 3 : 2) * dpr;
    ctx.lineCap = "round";
    ctx.beginPath();
    for (const [p, j] of take.bones) segment(placed(take, P, base, p), placed(take, P, base, j));
    ctx.stroke();
    ctx.fillStyle = colour;
    for (const s of screenPoints(take, P, i)) {
      if (!s) continue;
      ctx.beginPath();
      ctx.arc(s[0], s[1], (main ? 3 : 2) * dpr, 0, 2 * Math.PI);
      ctx.fill();
    }
    // contacts: a ring on the floor under each planted foot, and the foot point marked
    for (const { j, flags } of take.plantRows) {
      if (!flags[i]) continue;
      const p = placed(take, P, base, j);
      ctx.strokeStyle = "#1a9e3a";
      ctx.fillStyle = "#1a9e3a";
      ctx.lineWidth = 2 * dpr;
      ctx.beginPath();
      const r = 0.08 / take.metersPerUnit;
      for (let k = 0; k <= 24; k++) {
        const a = (k / 24) * 2 * Math.PI;
        const s = project(p[0] + r * Math.cos(a), S.floor, p[2] + r * Math.sin(a));
        if (s) (k ? ctx.lineTo : ctx.moveTo).call(ctx, s[0], s[1]);
      }
      ctx.stroke();
      const s = project(...p);
      if (s) {
        ctx.beginPath();
        ctx.arc(s[0], s[1], 5 * dpr, 0, 2 * Math.PI);
        ctx.fill();
      }
    }
    ctx.globalAlpha = 1;
  }

  function drawView() {
    resizeCanvas(view);
    updateBasis();
    ctx.clearRect(0, 0, view.width, view.height);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, view.width, view.height);
    drawGrid();
    const t = take0();
    for (const take of S.takes.slice(1)) drawSkeleton(take, take.positions, shownIndex(take), take.colour, 0.45, false);
    if (S.edited && S.preview) drawSkeleton(t, t.positions, S.cur, "#888", 0.35, false);
    const P = shownPositions(t);
    drawSkeleton(t, P, S.cur, t.colour, 1, true);
    const s = S.selected >= 0 ? project(...placed(t, P, S.cur * t.joints.length * 3, S.selected)) : null;
    if (s) {
      const dpr = window.devicePixelRatio || 1;
      ctx.fillStyle = "#e07000";
      ctx.strokeStyle = "#fff";
      ctx.lineWidth = 2 * dpr;
      ctx.beginPath();
      ctx.arc(s[0], s[1], 6 * dpr, 0, 2 * Math.PI);
      ctx.fill();
      ctx.stroke();
    }
  }

  /* ---------- joint panel ---------- */

  function formatValue(v) {
    return Number.isFinite(v) ? String(Number(v.toPrecision(8))) : String(v);
  }

  /* the table is rebuilt when the joint changes; on other frames only its values are rewritten */
  function updateJointPanel() {
    const t = take0(), j = S.selected;
    if (S.panelJoint === j && j >= 0) {
      for (const [cell, take, column] of S.panelCells) {
        const v = shownValues(take)[indexAt(take, S.time) * take.channelCount + column];
        cell.textContent = formatValue(v);
        cell.dataset.value = String(v);
      }
      updateGlyph();
      return;
    }
    S.panelJoint = j;
    S.panelCells = [];
    const body = $("channels").tBodies[0];
    body.textContent = "";
    $("joint-name").textContent = j >= 0 ? t.points[j] : "none";
    if (j < 0) return;
    const name = t.joints[j];
    const head = body.insertRow();
    head.insertCell().textContent = "";
    for (const take of S.takes) {
      const cell = head.insertCell();
      cell.textContent = take.name;
      cell.title = take.name; // cut short by the style (HDM05's names are long): the whole name on hover
      cell.className = "take";
      cell.style.color = take.colour;
    }
    const dofs = t.dofs[j];
    if (!dofs.length) body.insertRow().insertCell().textContent = "(no channels)";
    dofs.forEach((dof) => {
      const row = body.insertRow();
      row.insertCell().textContent = dof;
      for (const take of S.takes) {
        const cell = row.insertCell();
        cell.className = "v";
        const k = take.jointIndex.get(name);
        const at = k === undefined ? -1 : take.dofs[k].indexOf(dof);
        if (at < 0) continue;
        cell.dataset.dof = dof;
        cell.dataset.take = String(take.index);
        S.panelCells.push([cell, take, take.firstColumn[k] + at]);
      }
    });
    updateJointPanel();
  }

  /* the selected joint's own rotation (C M C^T) at the current frame as an axis and an angle */
  function updateGlyph() {
    const t = take0(), j = S.selected, J = t.joints.length;
    const pos = new Float64Array(J * 3), world = new Float64Array(J * 9), local = new Float64Array(J * 9);
    fkFrame(t, shownValues(t), S.cur * t.channelCount, pos, 0, world, local);
    const v = quaternionToRotvec(matrixToQuaternion(local, 9 * j));
    const angle = Math.hypot(v[0], v[1], v[2]);
    const axis = angle > 0 ? v.map((c) => c / angle) : [0, 1, 0];
    const box = $("axis-angle");
    box.dataset.rotvec = JSON.stringify(v);
    box.textContent = `${((angle * 180) / Math.PI).toFixed(2)}\u00b0 about (${axis.map((c) => c.toFixed(3)).join(", ")})`;
    const g = $("glyph"), c = g.getContext("2d"), W = g.width, R = W * 0.38;
    c.clearRect(0, 0, W, W);
    c.strokeStyle = "#bbb";
    c.lineWidth = 1;
    c.beginPath();
    c.arc(W / 2, W / 2, R, 0, 2 * Math.PI);
    c.stroke();
    if (!basis) return;
    // screen-space direction of a direction in the take's axes, turned as the 3D view draws it
    const T = t.turn;
    const dir = (v) => {
      const d = [0, 1, 2].map((e) => T[3 * e] * v[0] + T[3 * e + 1] * v[1] + T[3 * e + 2] * v[2]);
      return [d[0] * basis.r[0] + d[1] * basis.r[1] + d[2] * basis.r[2], d[0] * basis.u[0] + d[1] * basis.u[1] + d[2] * basis.u[2]];
    };
    const toG = (d, s) => [W / 2 + s * R * d[0], W / 2 - s * R * d[1]];
    for (const [e, name] of [[[1, 0, 0], "x"], [[0, 1, 0], "y"], [[0, 0, 1], "z"]]) {
      const p = toG(dir(e), 0.5);
      c.strokeStyle = AXIS_COLOURS[name];
      c.beginPath();
      c.moveTo(W / 2, W / 2);
      c.lineTo(p[0], p[1]);
      c.stroke();
    }
    // the arc swept by the angle about the axis, on a circle around it
    const ref = Math.abs(axis[1]) < 0.9 ? [0, 1, 0] : [1, 0, 0];
    const u = norm(cross(axis, ref)), w = cross(axis, u);
    c.strokeStyle = "#e07000";
    c.lineWidth = 3;
    c.beginPath();
    const steps = 40;
    for (let k = 0; k <= steps; k++) {
      const a = (k / steps) * angle;
      const d = [0, 1, 2].map((e) => 0.35 * axis[e] + 0.7 * (Math.cos(a) * u[e] + Math.sin(a) * w[e]));
      const p = toG(dir(d), 1);
      (k ? c.lineTo : c.moveTo).call(c, p[0], p[1]);
    }
    c.stroke();
    const tip = toG(dir(axis), 1);
    c.strokeStyle = "#222";
    c.lineWidth = 2;
    c.beginPath();
    c.moveTo(W / 2, W / 2);
    c.lineTo(tip[0], tip[1]);
    c.stroke();
    c.fillStyle = "#222";
    c.beginPath();
    c.arc(tip[0], tip[1], 3, 0, 2 * Math.PI);
    c.fill();
  }

  function select(j) {
    S.selected = j;
    for (const el of document.querySelectorAll(".jname")) el.classList.toggle("selected", Number(el.dataset.joint) === j);
    S.dirtyCurves = true;
    S.dirty = true;
    updateJointPanel();
  }

  function buildTree() {
    const t = take0(), tree = $("tree");
    const node = (j) => {
      const div = document.createElement("div");
      div.className = "node";
      div.setAttribute("role", "treeitem");
      const row = document.createElement("div");
      row.className = "row";
      const caret = document.createElement("button");
      const kids = t.children[j];
      caret.className = "caret" + (kids.length ? "" : " leaf");
      caret.textContent = "\u25be";
      caret.title = "collapse / expand";
      caret.addEventListener("click", () => {
        div.classList.toggle("collapsed");
        caret.textContent = div.classList.contains("collapsed") ? "\u25b8" : "\u25be";
      });
      const name = document.createElement("button");
      name.className = "jname";
      name.textContent = t.points[j];
      name.dataset.joint = String(j);
      name.dataset.name = t.joints[j];
      name.addEventListener("click", () => select(j));
      row.append(caret, name);
      div.append(row);
      for (const k of kids) div.append(node(k));
      return div;
    };
    tree.append(node(t.order[0]));
  }

  /* ---------- curves ---------- */

  const curves = $("curves");
  const cctx = curves.getContext("2d");
  const overlay = $("playhead");
  let curveBase = null;
  const M = { left: 56, right: 10, top: 8, bottom: 20 };

  function curveGeometry() {
    const dpr = window.devicePixelRatio || 1;
    const plantRows = S.takes.reduce((n, t) => n + t.plantRows.length, 0);
    const strip = plantRows ? plantRows * 7 + 4 : 0;
    const W = curves.width, H = curves.height;
    const x0 = M.left * dpr, x1 = W - M.right * dpr, y0 = M.top * dpr, y1 = H - (M.bottom + strip) * dpr;
    const T = Math.max(...S.takes.map(duration), 1e-9);
    return { dpr, W, H, x0, x1, y0, y1, T, strip: strip * dpr, xOf: (time) => x0 + ((x1 - x0) * time) / T, timeOf: (x) => ((x - x0) / (x1 - x0)) * T };
  }

  function drawCurveBase() {
    resizeCanvas(curves);
    const G = curveGeometry(), t = take0();
    const c = cctx;
    c.fillStyle = "#fff";
    c.fillRect(0, 0, G.W, G.H);
    c.font = `${11 * G.dpr}px system-ui, sans-serif`;
    const j = S.selected >= 0 ? S.selected : 0, name = t.joints[j];
    const series = [];
    S.takes.forEach((take) => {
      const k = take.jointIndex.get(name);
      if (k === undefined) return;
      const sources = take.index === 0 && S.edited && S.preview ? [[S.edited, false], [take.values, true]] : [[take.values, take.index > 0]];
      for (const [values, ghost] of sources)
        take.dofs[k].forEach((dof, i) => series.push({ take, values, ghost, dof, col: take.firstColumn[k] + i }));
    });
    let lo = Infinity, hi = -Infinity;
    for (const s of series)
      for (let f = 0; f < s.take.frames; f++) {
        const v = s.values[f * s.take.channelCount + s.col];
        if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
      }
    if (!Number.isFinite(lo)) { lo = -1; hi = 1; }
    if (hi - lo < 1e-9) { lo -= 1; hi += 1; }
    const pad = 0.05 * (hi - lo);
    lo -= pad; hi += pad;
    const yOf = (v) => G.y1 - ((G.y1 - G.y0) * (v - lo)) / (hi - lo);
    // axes and ticks
    c.strokeStyle = "#ddd";
    c.fillStyle = "#777";
    c.lineWidth = G.dpr;
    c.textAlign = "right";
    c.textBaseline = "middle";
    for (const v of ticks(lo, hi, 5)) {
      c.beginPath(); c.moveTo(G.x0, yOf(v)); c.lineTo(G.x1, yOf(v)); c.stroke();
      c.fillText(String(Number(v.toPrecision(6))), G.x0 - 4 * G.dpr, yOf(v));
    }
    c.textAlign = "center";
    c.textBaseline = "top";
    for (const time of ticks(0, G.T, 10)) {
      const x = G.xOf(time);
      c.beginPath(); c.moveTo(x, G.y0); c.lineTo(x, G.y1); c.stroke();
      c.fillText(`${Number(time.toPrecision(6))} s`, x, G.y1 + 4 * G.dpr);
    }
    // series: the shown take solid, the compared and the unedited ones dashed
    for (const s of series) {
      const take = s.take, C = take.channelCount;
      c.strokeStyle = AXIS_COLOURS[s.dof[1] || "l"] || "#555";
      c.globalAlpha = s.ghost ? 0.6 : 1;
      c.setLineDash(s.ghost ? [4 * G.dpr, 3 * G.dpr] : []);
      c.lineWidth = (s.ghost ? 1 : 1.5) * G.dpr;
      c.beginPath();
      let pen = false;
      for (let f = 0; f < take.frames; f++) {
        const v = s.values[f * C + s.col];
        if (!Number.isFinite(v)) { pen = false; continue; }
        const x = G.xOf((f * take.step) / take.frameRate), y = yOf(v);
        if (pen) c.lineTo(x, y); else c.moveTo(x, y);
        pen = true;
      }
      c.stroke();
    }
    c.setLineDash([]);
    c.globalAlpha = 1;
    // footplant strip: one row per foot per take
    let row = 0;
    for (const take of S.takes)
      for (const { label, flags } of take.plantRows) {
        const y = G.y1 + M.bottom * G.dpr + 2 * G.dpr + row * 7 * G.dpr;
        c.fillStyle = take.colour;
        for (let f = 0; f < take.frames; f++) {
          if (!flags[f]) continue;
          const x = G.xOf((f * take.step) / take.frameRate);
          c.fillRect(x, y, Math.max(1, G.xOf(((f + 1) * take.step) / take.frameRate) - x), 5 * G.dpr);
        }
        c.textAlign = "right";
        c.textBaseline = "top";
        c.font = `${8 * G.dpr}px system-ui, sans-serif`;
        c.fillText(label, G.x0 - 4 * G.dpr, y - G.dpr);
        row++;
      }
    c.textAlign = "left";
    c.textBaseline = "top";
    c.font = `${11 * G.dpr}px system-ui, sans-serif`;
    c.fillStyle = "#333";
    let x = G.x0 + 4 * G.dpr;
    const label = (text, colour) => {
      c.fillStyle = colour;
      c.fillText(text, x, G.y0 + 2 * G.dpr);
      x += c.measureText(text + " ").width;
    };
    label(`${t.points[j]}:`, "#333");
    if (!t.dofs[j].length) label("no channels", "#333");
    for (const dof of t.dofs[j]) label(dof, AXIS_COLOURS[dof[1] || "l"] || "#555");
    if (S.takes.length > 1 || (S.edited && S.preview)) label(S.edited && S.preview ? "(dashed: before editing, compared takes)" : "(dashed: compared takes)", "#777");
    curveBase = { width: curves.width, height: curves.height, G };
    S.dirtyCurves = false;
  }

  function ticks(lo, hi, count) {
    const span = hi - lo;
    if (!(span > 0)) return [lo];
    const raw = span / count, mag = 10 ** Math.floor(Math.log10(raw));
    const step = [1, 2, 5, 10].map((k) => k * mag).find((s) => s >= raw);
    const out = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) out.push(Math.abs(v) < 1e-12 * step ? 0 : v);
    return out;
  }

  /* the curves are drawn when they change; the playhead and the selection over them on every frame */
  function drawCurves() {
    resizeCanvas(curves);
    if (S.dirtyCurves || !curveBase || curveBase.width !== curves.width || curveBase.height !== curves.height) drawCurveBase();
    const { G } = curveBase, t = take0(), c = overlay.getContext("2d");
    if (overlay.width !== curves.width || overlay.height !== curves.height) {
      overlay.width = curves.width;
      overlay.height = curves.height;
    }
    c.clearRect(0, 0, overlay.width, overlay.height);
    if (S.selection) {
      const [a, b] = S.selection;
      const xa = G.xOf((a * t.step) / t.frameRate), xb = G.xOf((b * t.step) / t.frameRate);
      c.fillStyle = "rgba(224,112,0,0.15)";
      c.fillRect(xa, G.y0, xb - xa, G.y1 - G.y0);
    }
    const x = G.xOf(S.time);
    c.strokeStyle = "#e07000";
    c.lineWidth = 1.5 * G.dpr;
    c.beginPath();
    c.moveTo(x, G.y0);
    c.lineTo(x, G.H);
    c.stroke();
  }

  /* ---------- editor ---------- */

  function stepSpec(kind) {
    return DATA.steps.find((s) => s.kind === kind);
  }

  function jointsFor(choice) {
    const t = take0();
    if (choice === "all") return null;
    const j = S.selected >= 0 ? S.selected : 0;
    if (choice === "selected") return [t.joints[j]];
    const out = [], visit = (k) => { out.push(t.joints[k]); t.children[k].forEach(visit); };
    visit(j);
    return out;
  }

  /* the stack as a recipe for motiontheater: TOML [[step]] tables, frames in frame numbers */
  function recipe() {
    const t = take0();
    const q = (s) => JSON.stringify(s); // a JSON string is a valid TOML basic string
    const lines = [`# motiontheater recipe, made in the viewer for ${t.name}`, `# apply: ${DATA.applyHint.replace("TAKE", t.name)}`];
    for (const s of S.stack) {
      const spec = stepSpec(s.kind);
      lines.push("", "[[step]]", `run = ${q(spec.run)}`);
      for (const [key, value] of Object.entries(spec.options)) lines.push(`${key} = ${typeof value === "string" ? q(value) : value}`);
      if (spec.size) lines.push(`size = ${s.size}`);
      lines.push(`frames = [${s.first}, ${s.last}]`);
      if (s.joints) lines.push(`joints = [${s.joints.map(q).join(", ")}]`);
    }
    return lines.join("\n") + "\n";
  }

  function recompute() {
    const t = take0();
    if (!S.stack.length) {
      S.edited = S.editedPositions = null;
    } else {
      let values = t.values;
      for (const s of S.stack) values = applyStep(t, values, s);
      S.edited = values;
      S.editedPositions = allPositions(t, values);
    }
    const list = $("stack");
    list.textContent = "";
    S.stack.forEach((s, i) => {
      const li = document.createElement("li");
      const size = stepSpec(s.kind).size ? ` ${s.size}` : "";
      li.textContent = `${s.kind}${size}, frames ${s.first}..${s.last}, ${s.joints ? s.joints.join(" ") : "all joints"}`;
      const remove = document.createElement("button");
      remove.textContent = "\u00d7";
      remove.title = "remove this step";
      remove.addEventListener("click", () => { S.stack.splice(i, 1); recompute(); });
      li.append(remove);
      list.append(li);
    });
    $("recipe").value = S.stack.length ? recipe() : "";
    S.dirtyCurves = S.dirty = true;
    updateJointPanel();
  }

  function addStep(step) {
    const t = take0(), spec = stepSpec(step.kind);
    const f0 = t.firstFrame, f1 = t.firstFrame + t.frames - 1;
    if (!spec) throw new Error(`unknown step ${step.kind}`);
    if (!(Number.isInteger(step.first) && Number.isInteger(step.last) && f0 <= step.first && step.first < step.last && step.last <= f1))
      throw new Error(`frames must satisfy ${f0} <= first < last <= ${f1}`);
    for (const joint of step.joints || []) if (!t.jointIndex.has(joint)) throw new Error(`no joint '${joint}' in ${t.name}`);
    if (spec.size && !(Number.isInteger(step.size) && step.size >= 1 && step.size % 2 === 1))
      throw new Error("size must be an odd number of frames (1, 3, 5, ...)");
    S.stack.push({ kind: step.kind, first: step.first, last: step.last, joints: step.joints || null, size: spec.size ? step.size : null });
    recompute();
  }

  function setUpEditor() {
    const kind = $("e-kind");
    for (const s of DATA.steps) {
      const o = document.createElement("option");
      o.value = s.kind;
      o.textContent = s.kind;
      o.title = s.label;
      kind.append(o);
    }
    const sizeShown = () => {
      $("e-size-label").hidden = !stepSpec(kind.value).size;
      $("e-what").textContent = stepSpec(kind.value).label;
    };
    kind.addEventListener("change", sizeShown);
    sizeShown();
    if (!DATA.editable) {
      $("editor").hidden = true;
      return;
    }
    $("e-add").addEventListener("click", () => {
      try {
        addStep({ kind: kind.value, first: Number($("e-from").value), last: Number($("e-to").value), size: Number($("e-size").value), joints: jointsFor($("e-joints").value) });
        $("e-message").textContent = "";
      } catch (err) {
        $("e-message").textContent = err.message;
      }
    });
    $("e-preview").addEventListener("change", (e) => { S.preview = e.target.checked; S.dirtyCurves = S.dirty = true; updateJointPanel(); });
    $("e-copy").addEventListener("click", async () => {
      const text = $("recipe").value;
      try {
        await navigator.clipboard.writeText(text);
      } catch (err) {
        $("recipe").select();
        document.execCommand("copy");
      }
      $("e-message").textContent = "copied";
    });
    $("e-download").addEventListener("click", () => {
      const a = document.createElement("a");
      a.href = URL.createObjectURL(new Blob([$("recipe").value], { type: "application/toml" }));
      a.download = take0().name.replace(/\.[^.]*$/, "") + ".recipe.toml";
      document.body.append(a);
      a.click();
      a.remove();
    });
  }

  function setSelection(a, b) {
    const t = take0();
    S.selection = a === null ? null : [Math.min(a, b), Math.max(a, b)];
    if (S.selection) {
      $("e-from").value = frameNumber(t, S.selection[0]);
      $("e-to").value = frameNumber(t, S.selection[1]);
    }
    S.dirty = true;
  }

  /* ---------- controls ---------- */

  function setToggle(id, on) {
    $(id).setAttribute("aria-pressed", on ? "true" : "false");
  }

  function togglePlay(on = !S.playing) {
    const t = take0();
    if (on && !S.loop && !S.reverse && S.cur === t.frames - 1) seek(0);
    if (on && !S.loop && S.reverse && S.cur === 0) seek(t.frames - 1);
    S.playing = on;
    S.last = null;
    $("b-play").textContent = on ? "\u2759\u2759" : "\u25b6";
    S.dirty = true;
  }

  function updateClock() {
    const t = take0();
    const frame = frameNumber(t, S.cur);
    const field = $("frame");
    if (document.activeElement !== field) field.value = frame;
    $("slider").value = S.cur;
    $("clock").textContent = `frame ${frame} of ${frameNumber(t, 0)}..${frameNumber(t, t.frames - 1)} \u00b7 ${S.time.toFixed(3)} s / ${duration(t).toFixed(3)} s \u00b7 ${t.frameRate / t.step} Hz`;
    document.body.dataset.frame = String(frame);
    const planted = $("planted");
    planted.hidden = !t.plantRows.length;
    planted.textContent = "planted: " + (t.plantRows.filter((r) => r.flags[S.cur]).map((r) => r.label).join(", ") || "none");
  }

  function setUpControls() {
    const t = take0();
    $("slider").max = t.frames - 1;
    $("frame").min = frameNumber(t, 0);
    $("frame").max = frameNumber(t, t.frames - 1);
    $("b-play").addEventListener("click", () => togglePlay());
    $("b-back").addEventListener("click", () => { togglePlay(false); seek(S.cur - 1); });
    $("b-fwd").addEventListener("click", () => { togglePlay(false); seek(S.cur + 1); });
    $("b-first").addEventListener("click", () => seek(0));
    $("b-last").addEventListener("click", () => seek(t.frames - 1));
    const flip = (key, id) => () => { S[key] = !S[key]; setToggle(id, S[key]); S.dirty = true; };
    $("b-reverse").addEventListener("click", flip("reverse", "b-reverse"));
    $("b-loop").addEventListener("click", flip("loop", "b-loop"));
    $("b-follow").addEventListener("click", flip("follow", "b-follow"));
    $("b-speed").addEventListener("click", () => { S.speed = S.speed === 1 ? 2 : 1; setToggle("b-speed", S.speed === 2); });
    setToggle("b-reverse", S.reverse);
    setToggle("b-loop", S.loop);
    setToggle("b-follow", S.follow);
    setToggle("b-speed", S.speed === 2);
    $("slider").addEventListener("input", (e) => seek(Number(e.target.value)));
    $("frame").addEventListener("change", (e) => {
      if (e.target.value.trim() !== "" && Number.isFinite(Number(e.target.value))) seek((Number(e.target.value) - t.firstFrame) / t.step);
    });
    $("b-help").addEventListener("click", () => ($("help").hidden = !$("help").hidden));
    document.addEventListener("keydown", (e) => {
      const tag = e.target.tagName;
      if (tag === "INPUT" || tag === "SELECT" || tag === "TEXTAREA") return;
      const big = e.shiftKey ? 10 : 1;
      const keys = {
        " ": () => togglePlay(),
        ArrowLeft: () => { togglePlay(false); seek(S.cur - big); },
        ArrowRight: () => { togglePlay(false); seek(S.cur + big); },
        Home: () => seek(0),
        End: () => seek(t.frames - 1),
        r: () => $("b-reverse").click(),
        d: () => $("b-speed").click(),
        l: () => $("b-loop").click(),
        f: () => $("b-follow").click(),
        "[": () => setSelection(S.cur, S.selection ? S.selection[1] : t.frames - 1),
        "]": () => setSelection(S.selection ? S.selection[0] : 0, S.cur),
        "?": () => $("b-help").click(),
        Escape: () => ($("help").hidden = true),
      };
      const action = keys[e.key.length === 1 ? e.key.toLowerCase() : e.key] || keys[e.key];
      if (action) {
        e.preventDefault();
        action();
      }
    });
    // 3D view: orbit, pan, zoom, pick
    let drag = null;
    view.addEventListener("contextmenu", (e) => e.preventDefault());
    view.addEventListener("pointerdown", (e) => {
      drag = { x: e.clientX, y: e.clientY, moved: false, pan: e.button === 2 || e.shiftKey };
      view.setPointerCapture(e.pointerId);
    });
    view.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 2) drag.moved = true;
      drag.x = e.clientX;
      drag.y = e.clientY;
      if (drag.pan) {
        const k = (cam.dist * 2 * Math.tan(cam.fov / 2)) / view.clientHeight;
        for (let e3 = 0; e3 < 3; e3++) cam.pan[e3] += k * (-dx * basis.r[e3] + dy * basis.u[e3]);
      } else {
        cam.yaw -= dx * 0.01;
        cam.pitch = Math.min(1.5, Math.max(-1.5, cam.pitch + dy * 0.01));
      }
      S.dirty = true;
    });
    view.addEventListener("pointerup", (e) => {
      if (drag && !drag.moved) pick(e);
      drag = null;
    });
    view.addEventListener("wheel", (e) => {
      e.preventDefault();
      cam.dist *= Math.exp(e.deltaY * 0.001);
      S.dirty = true;
    }, { passive: false });
    // curves: click to seek, drag to select frames
    let cdrag = null;
    const indexOfX = (e) => {
      const r = curves.getBoundingClientRect(), G = curveBase.G;
      return indexAt(t, G.timeOf((e.clientX - r.left) * G.dpr));
    };
    curves.addEventListener("pointerdown", (e) => {
      cdrag = { start: indexOfX(e), x: e.clientX, moved: false };
      curves.setPointerCapture(e.pointerId);
    });
    curves.addEventListener("pointermove", (e) => {
      if (!cdrag) return;
      if (Math.abs(e.clientX - cdrag.x) > 3) cdrag.moved = true;
      if (cdrag.moved) setSelection(cdrag.start, indexOfX(e));
    });
    curves.addEventListener("pointerup", (e) => {
      if (cdrag && !cdrag.moved) seek(indexOfX(e));
      cdrag = null;
    });
    window.addEventListener("resize", () => { S.dirty = S.dirtyCurves = true; });
  }

  function pick(e) {
    const t = take0(), r = view.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
    const x = (e.clientX - r.left) * dpr, y = (e.clientY - r.top) * dpr;
    const shown = screenPoints(t, shownPositions(t), S.cur);
    let best = -1, bestD = 12 * dpr;
    for (let j = 0; j < t.joints.length; j++) {
      const s = shown[j];
      if (!s) continue;
      const d = Math.hypot(s[0] - x, s[1] - y);
      if (d < bestD) { best = j; bestD = d; }
    }
    if (best >= 0) select(best);
  }

  /* ---------- the loop ---------- */

  function tick(now) {
    const t = take0();
    S.stats.ticks++;
    if (S.playing) {
      S.stats.playTicks++;
      if (S.last != null) {
        const T = duration(t);
        S.time += (((now - S.last) / 1000) * S.speed) * (S.reverse ? -1 : 1);
        if (S.time > T || S.time < 0) {
          if (S.loop && T > 0) S.time = ((S.time % T) + T) % T;
          else {
            S.time = Math.min(T, Math.max(0, S.time));
            togglePlay(false);
          }
        }
        const i = indexAt(t, S.time);
        if (i !== S.cur) S.cur = i;
      }
      S.last = now;
      S.dirty = true;
    }
    if (S.dirty) {
      const start = performance.now();
      S.dirty = false;
      drawView();
      drawCurves();
      updateClock();
      if (S.selected >= 0 && S.shownCur !== S.cur) updateJointPanel();
      S.shownCur = S.cur;
      const ms = performance.now() - start;
      S.stats.drawMs += ms;
      S.stats.maxDrawMs = Math.max(S.stats.maxDrawMs, ms);
    }
    requestAnimationFrame(tick);
  }

  async function main() {
    S.takes = await Promise.all(DATA.takes.map(loadTake));
    const t = take0();
    const legend = $("legend");
    for (const take of S.takes) {
      const span = document.createElement("span");
      span.innerHTML = `<i style="background:${take.colour}"></i>`;
      span.append(take.name + (take.up === "y" ? "" : ` (up: ${take.up})`));
      legend.append(span);
    }
    if (DATA.note) {
      $("note").textContent = DATA.note;
      $("note").hidden = false;
    }
    // each take drawn standing along +y (its own turn), compared takes in the first take's length unit
    for (const take of S.takes) {
      const k = take.metersPerUnit / t.metersPerUnit;
      take.place = take.turn.map((v) => v * k);
    }
    setUpCamera();
    buildTree();
    setUpControls();
    setUpEditor();
    fromAddress();
    window.addEventListener("hashchange", fromAddress);
    $("e-from").value = frameNumber(t, 0);
    $("e-to").value = frameNumber(t, Math.min(t.frames - 1, 1));
    drawView();
    drawCurves();
    updateClock();
    window.mtView.ready = true;
    document.body.dataset.ready = "1";
    performance.mark("mt-ready");
    requestAnimationFrame(tick);
  }

  /* for scripts and tests: the state and the functions behind the controls */
  window.mtView = {
    ready: false,
    state: S,
    seek: (i) => seek(i),
    select: (name) => select(take0().jointIndex.get(name)),
    play: () => togglePlay(true),
    pause: () => togglePlay(false),
    addStep: (step) => addStep(step),
    clearSteps: () => { S.stack = []; recompute(); },
    recipe: () => (S.stack.length ? recipe() : ""),
    values: (k = 0, edited = true) => Array.from(k === 0 && edited && S.edited ? S.edited : S.takes[k].values),
    // positions in the take's own axes, as motiontheater computes them; project takes a point as drawn
    positions: (k = 0, i = 0) => {
      const take = S.takes[k], J = take.joints.length;
      return Array.from(take.positions.subarray(i * J * 3, (i + 1) * J * 3));
    },
    project: (x, y, z) => (basis ? project(x, y, z) : null),
    // the canvas pixels [x, y] of take k's joints as drawn at the shown frame (null: not drawn), and its bones
    drawn: (k = 0) => (basis ? screenPoints(S.takes[k], shownPositions(S.takes[k]), shownIndex(S.takes[k])) : null),
    bones: (k = 0) => S.takes[k].bones.map(([p, j]) => [S.takes[k].joints[p], S.takes[k].joints[j]]),
  };

  main().catch((err) => {
    fail("the viewer could not start: " + err.message);
    console.error(err);
  });
})();
