"""Incident and reflected wave amplitudes over time, from an array of gauges (posidonia_flume --gauges).

Usage: /usr/bin/python3 examples/posidonia_flume/reflection_history.py RUN_DIR[=LABEL]... --gauges x1,x2,...
       [--window PERIODS] [--local x1,x2,...] [--csv FILE] [--plot PNG]

For each run, DIR/plants/gauges.csv is read, and at the gauges named by --gauges (m; they must lie between the paddle
and the first reflector, in one resolution) the elevation is fitted over sliding windows of PERIODS wave periods
(default 1, every half period) as an incident and a reflected wave at the paddle's frequency,
    eta(x, t) = A_I cos(omega t - k x - phi_I) + A_R cos(omega t + k x - phi_R) + mean,
by least squares over all gauges and samples in the window (Mansard & Funke 1980, Coast. Eng. Proc. 1980, with the
amplitudes of one frequency). k is the linear dispersion relation's at the example's depth and period. The CSV holds
per run and window: the window's centre, A_I and A_R (mm), K_r = A_R / A_I, the phase of the reflected wave at x = 0
relative to the incident one (rad), and the fit's residual (mm rms). --local adds, for each gauge named there, the
amplitude of the paddle's frequency at that gauge alone over the same windows (incident and reflected together), as
columns local_<x>_mm and as a third panel of the plot.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mean_flow import option, read_gauges  # noqa: E402  (the same option and gauges.csv readers)

T = 1.2        # wave period, s (the example's default)
DEPTH = 0.2    # m
G = 9.81


def wave_number(omega, depth):
    k = omega ** 2 / G
    for _ in range(50):  # Newton on omega^2 = g k tanh(k h)
        f = G * k * np.tanh(k * depth) - omega ** 2
        df = G * np.tanh(k * depth) + G * k * depth / np.cosh(k * depth) ** 2
        k -= f / df
    return k


def gauge_columns(run, xs, gauges):
    columns = []
    for x in gauges:
        j = int(np.argmin(np.abs(xs - x)))
        if abs(xs[j] - x) > 1e-6:
            sys.exit(f'{run}: no gauge at x = {x} m (gauges at {", ".join(f"{v:g}" for v in xs)})')
        columns.append(j)
    return columns


def history(run, gauges, periods, local=()):
    t, eta, xs = read_gauges(run)
    columns = gauge_columns(run, xs, gauges)
    local_columns = gauge_columns(run, xs, local)
    omega = 2 * np.pi / T
    k = wave_number(omega, DEPTH)
    rows = []
    start = 2 * T
    while start + periods * T <= t[-1] + 1e-9:
        w = (t >= start) & (t < start + periods * T)
        tt = np.concatenate([t[w]] * len(columns))
        xx = np.concatenate([np.full(w.sum(), xs[j]) for j in columns])
        ee = np.concatenate([eta[w, j] for j in columns])
        a = np.column_stack([np.cos(omega * tt - k * xx), np.sin(omega * tt - k * xx),
                             np.cos(omega * tt + k * xx), np.sin(omega * tt + k * xx), np.ones_like(tt)])
        c, *_ = np.linalg.lstsq(a, ee, rcond=None)
        incident, reflected = np.hypot(c[0], c[1]), np.hypot(c[2], c[3])
        phase = np.angle(complex(c[2], -c[3]) / complex(c[0], -c[1]))
        residual = np.sqrt(np.mean((ee - a @ c) ** 2))
        amplitudes = []
        for j in local_columns:
            b = np.column_stack([np.cos(omega * t[w]), np.sin(omega * t[w]), np.ones(w.sum())])
            d, *_ = np.linalg.lstsq(b, eta[w, j], rcond=None)
            amplitudes.append(1e3 * np.hypot(d[0], d[1]))
        rows.append((start + 0.5 * periods * T, 1e3 * incident, 1e3 * reflected, reflected / incident, phase,
                     1e3 * residual, *amplitudes))
        start += 0.5 * T
    return np.array(rows)


def main(argv):
    gauges, argv = option(argv, '--gauges')
    periods, argv = option(argv, '--window')
    csv_path, argv = option(argv, '--csv')
    plot_path, argv = option(argv, '--plot')
    local, argv = option(argv, '--local')
    local = [] if local is None else [float(v) for v in local.split(',')]
    if not argv or gauges is None:
        sys.exit(__doc__)
    gauges = [float(v) for v in gauges.split(',')]
    periods = 1.0 if periods is None else float(periods)
    runs = [(a.split('=')[0], a.split('=')[1] if '=' in a else a) for a in argv]
    results = {label: history(run, gauges, periods, local) for run, label in runs}
    for label, r in results.items():
        late = r[:, 0] >= 4.74
        print(f'{label:24s} from 4.74 s: incident {r[late, 1].mean():6.3f} mm (min {r[late, 1].min():6.3f}, '
              f'max {r[late, 1].max():6.3f}), K_r {100 * r[late, 3].mean():5.2f} % (max {100 * r[late, 3].max():5.2f}),'
              f' residual {r[late, 5].mean():5.3f} mm')
    if csv_path:
        with open(csv_path, 'w') as f:
            f.write(f'# reflection_history.py: incident and reflected amplitudes (mm) at the gauges x = '
                    f'{", ".join(f"{g:g}" for g in gauges)} m over windows of {periods:g} periods every half period; '
                    f'phase of the reflected wave against the incident at x = 0 (rad), fit residual (mm rms)\n')
            f.write('run,t,incident_mm,reflected_mm,K_r,phase,residual_mm' +
                    ''.join(f',local_{x:g}_mm' for x in local) + '\n')
            for label, r in results.items():
                for row in r:
                    f.write(label + ',' + ','.join(f'{v:.5g}' for v in row) + '\n')
    if plot_path:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        panels = 3 if local else 2
        fig, axes = plt.subplots(panels, 1, figsize=(9, 3 * panels), sharex=True)
        styles = ['-', '--', ':', '-.']
        for n, (label, r) in enumerate(results.items()):
            colour = f'C{n}'
            axes[0].plot(r[:, 0], r[:, 1], colour, label=label)
            axes[1].plot(r[:, 0], 100 * r[:, 3], colour, label=label)
            for i, x in enumerate(local):
                axes[2].plot(r[:, 0], r[:, 6 + i], colour, ls=styles[i % len(styles)],
                             label=f'{label}, x = {x:g} m')
        if local:
            axes[2].set_ylabel('amplitude at the gauge (mm)')
            axes[2].legend(fontsize=7, ncol=2)
        axes[0].set_ylabel('incident amplitude (mm)')
        axes[1].set_ylabel('K_r (%)')
        axes[-1].set_xlabel('t, window centre (s)')
        axes[0].set_title(f'waves at the gauges x = {", ".join(f"{g:g}" for g in gauges)} m')
        for ax in axes:
            ax.grid(alpha=0.3)
        axes[0].legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(plot_path, dpi=110)
        print('plot:', plot_path)


if __name__ == '__main__':
    main(sys.argv[1:])
