"""Built-in example data: synthetic captures that need no files."""

from __future__ import annotations

import numpy as np


def noisy_rotations(
    seconds: float = 10.0,
    frame_rate: float = 120.0,
    channels: int = 90,
    noise_deg: float = 1.5,
    spike_rate: float = 0.005,
    spike_deg: float = 40.0,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """A smooth joint-rotation capture and a noisy copy of it, both (frames, channels) in degrees.

    Each channel is a sum of three slow sinusoids (0.2-3 Hz, the band of human
    motion).  The noisy copy adds Gaussian jitter of ``noise_deg`` and, on a
    ``spike_rate`` share of samples, single-frame spikes of about
    ``spike_deg``: the marker pops and label swaps that optical captures
    suffer.  The default shape, 90 channels, is the thesis's scene of 30
    joints with 3 rotation values each.
    """
    rng = np.random.default_rng(seed)
    frames = round(seconds * frame_rate)
    t = np.arange(frames)[:, None] / frame_rate
    freq = rng.uniform(0.2, 3.0, (3, channels))
    amp = rng.uniform(5.0, 45.0, (3, channels))
    phase = rng.uniform(0, 2 * np.pi, (3, channels))
    clean = sum(amp[i] * np.sin(2 * np.pi * freq[i] * t + phase[i]) for i in range(3))
    noisy = clean + rng.normal(0.0, noise_deg, clean.shape)
    spikes = rng.random(clean.shape) < spike_rate
    noisy[spikes] += rng.choice([-1.0, 1.0], spikes.sum()) * rng.uniform(0.5, 1.0, spikes.sum()) * spike_deg
    return clean, noisy
