"""Linear-theory wave train of a ramped piston: the paddle excursion (half-cosine ramp over 2 periods, then
(S/2) sin(omega t)) is Fourier transformed, each frequency is given Biesel's piston ratio H/S at its own k h and
propagated with its own k from the dispersion relation, and the elevation is transformed back at gauges 0.5-5 L
from the paddle. Prints the height of every zero up-crossing wave and the mean over the window the wave_flume
example opened in session 1 (ramp + x / c_g + T). Usage: linear_front.py [H T h] (default 0.028 1.4286 0.16)."""
import sys

import numpy as np

g = 9.81
H, T, h = (float(v) for v in sys.argv[1:4]) if len(sys.argv) > 3 else (0.028, 1.4286, 0.16)
w0 = 2 * np.pi / T


def wave_number(w):
    """k solving w^2 = g k tanh(k h), Newton from Eckart's estimate."""
    w = np.atleast_1d(np.abs(w)).astype(float)
    k = np.maximum(w * w / g / np.sqrt(np.tanh(w * w * h / g) + 1e-300), 1e-12)
    for _ in range(60):
        k = k - (g * k * np.tanh(k * h) - w * w) / (g * np.tanh(k * h) + g * k * h / np.cosh(k * h) ** 2)
    return k


def piston_ratio(kh):
    return 4 * np.sinh(kh) ** 2 / (np.sinh(2 * kh) + 2 * kh)


k0 = wave_number(w0)[0]
L, kh = 2 * np.pi / k0, k0 * h
stroke = H / piston_ratio(kh)
cg = 0.5 * (1 + 2 * kh / np.sinh(2 * kh)) * w0 / k0
dt, n = T / 40, 2**16
t = np.arange(n) * dt
ramp_time = 2 * T
r = np.where(t < ramp_time, 0.5 * (1 - np.cos(np.pi * t / ramp_time)), 1.0)
X = 0.5 * stroke * r * np.sin(w0 * t) * (t < 300)  # a long record, stopped far beyond the times looked at
spectrum = np.fft.rfft(X)
w = 2 * np.pi * np.fft.rfftfreq(n, dt)
k = np.zeros_like(w)
k[1:] = wave_number(w[1:])
ratio = np.zeros_like(w)
ratio[1:] = piston_ratio(k[1:] * h)
for x_over_L in [0.5, 1, 1.5, 2, 2.5, 3, 4, 5]:
    x = x_over_L * L
    eta = np.fft.irfft(spectrum * ratio * np.exp(-1j * k * x), n)
    up = [i for i in range(n - 1) if eta[i] < 0 <= eta[i + 1] and t[i] < 16]
    waves = [(t[a], (eta[a + 1 : b + 1].max() - eta[a + 1 : b + 1].min()) / H) for a, b in zip(up, up[1:])]
    window = [hh for tt, hh in waves if tt >= ramp_time + x / cg + T]
    print(f"x/L = {x_over_L}: " + " ".join(f"{tt:.1f}:{hh:.3f}" for tt, hh in waves if hh > 0.05)
          + f" | window mean {np.mean(window):.3f}")
