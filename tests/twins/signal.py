"""Slow twins of the signal kernels, written from their definitions (numpy and plain Python loops).

``TWINS`` maps each C entry point to its twin, for the table of one twin per
``mt_*`` function; every twin works along axis 0 of a (frames, channels) array.
"""

import math

import numpy as np

BINOMIAL5 = np.array([1.0, 4.0, 6.0, 4.0, 1.0]) / 16

# numpy.pad's names for the edge modes of mtcore (mt_mode)
PAD_MODES = {"reflect": "symmetric", "nearest": "edge", "mirror": "reflect", "wrap": "wrap", "constant": "constant"}


def extended(x, before, after, mode, cval=0.0):
    """x (frames, channels) extended by ``before`` and ``after`` frames as the mode says (np.pad)."""
    if mode == "constant":
        return np.pad(x, ((before, after), (0, 0)), mode="constant", constant_values=cval)
    return np.pad(x, ((before, after), (0, 0)), mode=PAD_MODES[mode])


def levels_twin(x, count, mode="nearest", cval=0.0):
    """The pyramid G_0 .. G_count: G_{k+1} = G_k correlated with (1 4 6 4 1) / 16, taps 2^k apart."""
    x = np.asarray(x, dtype=np.float64)
    levels = [x]
    for k in range(count):
        s = 2**k
        g = extended(levels[-1], 2 * s, 2 * s, mode, cval)
        n = len(x)
        levels.append(sum(w * g[2 * s + (j - 2) * s : 2 * s + (j - 2) * s + n] for j, w in enumerate(BINOMIAL5)))
    return levels


def equalize_twin(x, gains, mode="nearest", cval=0.0):
    """Bruderlin and Williams as defined: G_fb + sum_k g_k (G_k - G_{k+1}), fb = floor(log2 frames),
    gains after the last given 1."""
    n = len(x)
    fb = math.floor(math.log2(n)) if n else 0
    g = list(gains) + [1.0] * (fb - len(gains))
    levels = levels_twin(x, fb, mode, cval)
    return levels[fb] + sum(g[k] * (levels[k] - levels[k + 1]) for k in range(fb))


def sosfilt_zi_twin(sos):
    """Steady state of each section for a unit step, each section's gain carried to the next."""
    zi, scale = [], 1.0
    for b0, b1, b2, _, a1, a2 in sos:
        # z0 = b1 x - a1 y + z1, z1 = b2 x - a2 y with x = 1, y = b0 + z0: solve for z0, z1
        y = (b0 + b1 + b2) / (1 + a1 + a2)
        z1 = b2 - a2 * y
        z0 = y - b0
        zi.append((scale * z0, scale * z1))
        scale *= y
    return np.array(zi)


def _sosfilt(sos, x, zi):
    """Transposed direct form II, section by section, sample by sample (vectorised over channels)."""
    out = np.empty_like(x)
    z = [list(pair) for pair in zi]
    for t in range(len(x)):
        v = x[t]
        for s, (b0, b1, b2, _, a1, a2) in enumerate(sos):
            y = b0 * v + z[s][0]
            z[s][0] = b1 * v - a1 * y + z[s][1]
            z[s][1] = b2 * v - a2 * y
            v = y
        out[t] = v
    return out


def sosfiltfilt_twin(sos, x, padtype="odd", padlen=None):
    """Forward and backward filtering of the line extended at both ends (scipy's filtfilt recipe)."""
    sos = np.asarray(sos, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    if padtype is None:
        edge = 0
    elif padlen is None:
        edge = 3 * (2 * len(sos) + 1 - min((sos[:, 2] == 0).sum(), (sos[:, 5] == 0).sum()))
    else:
        edge = padlen
    if edge:
        left, right = x[edge:0:-1], x[-2 : -edge - 2 : -1]
        if padtype == "odd":
            left, right = 2 * x[0] - left, 2 * x[-1] - right
        elif padtype == "constant":
            left, right = np.repeat(x[:1], edge, axis=0), np.repeat(x[-1:], edge, axis=0)
        x = np.concatenate([left, x, right])
    zi = sosfilt_zi_twin(sos)
    forward = _sosfilt(sos, x, [z[:, None] * x[0] for z in zi])
    backward = _sosfilt(sos, forward[::-1], [z[:, None] * forward[-1] for z in zi])[::-1]
    return backward[edge : len(backward) - edge]


def upfirdn_twin(h, x, up, down):
    """Upsample by inserting up - 1 zeros, convolve with h in full, keep every down-th sample."""
    x = np.asarray(x, dtype=np.float64)
    stuffed = np.zeros(((len(x) - 1) * up + 1, x.shape[1]))
    stuffed[::up] = x
    full = np.stack([np.convolve(h, stuffed[:, c]) for c in range(x.shape[1])], axis=1)
    return full[::down]


def firwin_kaiser_twin(taps, cutoff, beta):
    """A windowed-sinc low pass, unit gain at 0: sinc times a Kaiser window (I0 by its series)."""

    def i0(v):
        term, total, k = 1.0, 1.0, 1
        while term > 1e-17 * total:
            term *= (v / (2 * k)) ** 2
            total += term
            k += 1
        return total

    alpha = (taps - 1) / 2
    h = []
    for i in range(taps):
        m = i - alpha
        window = i0(beta * math.sqrt(max(0.0, 1 - (m / alpha) ** 2))) / i0(beta)
        h.append(cutoff * (math.sin(math.pi * cutoff * m) / (math.pi * cutoff * m) if m else 1.0) * window)
    h = np.array(h)
    return h / h.sum()


def resample_poly_twin(x, up, down, padtype="constant", beta=5.0):
    """scipy's resample_poly recipe from the twins above: a Kaiser low pass at the lower Nyquist
    frequency, 20 max(up, down) + 1 taps, the line extended by (numpy) padding far enough, upfirdn,
    and the output aligned so that its sample 0 falls on input sample 0."""
    g = math.gcd(up, down)
    up, down = up // g, down // g
    x = np.asarray(x, dtype=np.float64)
    n = len(x)
    n_out = -(-n * up // down)
    half = 10 * max(up, down)
    h = firwin_kaiser_twin(2 * half + 1, 1 / max(up, down), beta) * up
    reach = 2 * half // up + 2  # input frames the filter reads past either end
    if padtype == "constant":
        padded = np.pad(x, ((reach, reach), (0, 0)))
    else:
        padded = np.pad(x, ((reach, reach), (0, 0)), mode={"edge": "edge", "symmetric": "symmetric"}[padtype])
    full = upfirdn_twin(h, padded, up, 1)  # the upsampled, filtered line, before taking every down-th
    # output j sits at upsampled position j * down of the line, half taps later in the full convolution
    start = reach * up + half
    return full[start : start + n_out * down : down]


def nan_runs_twin(x):
    """(column, first, stop) of every run of NaN, by column then frame."""
    runs = []
    x = np.asarray(x)
    for c in range(x.shape[1]):
        t = 0
        while t < len(x):
            if math.isnan(x[t, c]):
                start = t
                while t < len(x) and math.isnan(x[t, c]):
                    t += 1
                runs.append((c, start, t))
            else:
                t += 1
    return runs


def _spline_slopes(knots, values):
    """Slopes of the not-a-knot cubic spline through the knots, from its dense linear system."""
    k = len(knots)
    dx, dy = np.diff(knots), np.diff(values)
    slope = dy / dx
    if k == 2:
        return np.array([slope[0], slope[0]])
    if k == 3:  # the parabola through the three
        c = (slope[1] - slope[0]) / (knots[2] - knots[0])
        return np.array([slope[0] - c * dx[0], slope[0] + c * dx[0], slope[1] + c * dx[1]])
    a, b = np.zeros((k, k)), np.zeros(k)
    for i in range(1, k - 1):  # continuous second derivative at interior knots
        a[i, i - 1], a[i, i], a[i, i + 1] = dx[i], 2 * (dx[i - 1] + dx[i]), dx[i - 1]
        b[i] = 3 * (dx[i] * slope[i - 1] + dx[i - 1] * slope[i])
    # not-a-knot: the third derivative continuous at the second and the second-to-last knots
    d = knots[2] - knots[0]
    a[0, 0], a[0, 1] = dx[1], d
    b[0] = ((dx[0] + 2 * d) * dx[1] * slope[0] + dx[0] ** 2 * slope[1]) / d
    d = knots[-1] - knots[-3]
    a[-1, -2], a[-1, -1] = d, dx[-2]
    b[-1] = (dx[-1] ** 2 * slope[-2] + (2 * d + dx[-1]) * dx[-2] * slope[-1]) / d
    return np.linalg.solve(a, b)


def _hermite(knots, values, slopes, t):
    i = np.searchsorted(knots, t) - 1
    h = knots[i + 1] - knots[i]
    u = (t - knots[i]) / h
    h00, h10, h01, h11 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u, -2 * u**3 + 3 * u**2, u**3 - u**2
    return h00 * values[i] + h10 * h * slopes[i] + h01 * values[i + 1] + h11 * h * slopes[i + 1]


def fill_gaps_twin(x, max_gap, method="linear"):
    """(filled copy, unfilled runs): runs of NaN of at most max_gap frames with a sample on both
    sides filled linearly or by the not-a-knot spline through the stretch between unfilled runs."""
    x = np.array(x, dtype=np.float64)
    out = x.copy()
    n = len(x)
    for c, first, stop in nan_runs_twin(x):
        if first == 0 or stop == n or stop - first > max_gap:
            continue
        # the stretch: from after the previous unfilled run to before the next
        bounds = [(f, s) for cc, f, s in nan_runs_twin(x[:, c : c + 1]) if f == 0 or s == n or s - f > max_gap]
        lo = max([s for f, s in bounds if s <= first], default=0)
        hi = min([f for f, s in bounds if f >= stop], default=n)
        frames = np.arange(lo, hi)
        valid = ~np.isnan(x[lo:hi, c])
        knots, values = frames[valid].astype(float), x[lo:hi, c][valid]
        t = np.arange(first, stop, dtype=float)
        if method == "linear":
            out[first:stop, c] = np.interp(t, knots, values)
        else:
            out[first:stop, c] = _hermite(knots, values, _spline_slopes(knots, values), t)
    return out, nan_runs_twin(out)
