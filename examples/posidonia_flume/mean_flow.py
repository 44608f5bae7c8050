"""The slow part of a posidonia_flume run: the plant's mean position, the mean current beside it, and the long waves.

Usage: /usr/bin/python3 examples/posidonia_flume/mean_flow.py REFERENCE_DIR RUN_DIR... [--until T] [--csv FILE]
       [--plot PNG]

For each run folder (written with --runs plants or both), from DIR/plants/gauges.csv and DIR/plants/tips.csv:
  * H at each gauge against the reference run's (DIR/plants/wave_heights.csv), %;
  * the tip's half peak-to-peak excursion in x (the example's criterion) and the half peak-to-peak of its periodic
    part: 4 harmonics of the wave fitted together with a quadratic drift (as analysis::fit_harmonics), mm;
  * the tip's vertical half peak-to-peak excursion, mm;
  * the tip's mean displacement and the Eulerian mean current at the plant's mid-height, mm and mm/s;
  * the long waves: the mean level of each gauge over one wave period, every half period from 4.2 s on. "spread" is
    the mean over those windows of the largest difference between the gauges (a level gradient along the flume);
    "wander" the rms of each gauge's window means about their straight-line trend, averaged over the gauges, mm.
All over the window the example uses for the tip (from the ramp, the wave's travel to the plant and one period).
--until T ends every window at T s, so that the first part of a longer record can be compared with a shorter run:
H is then found from DIR/plants/gauges.csv by zero up-crossings (as analysis::zero_crossing_analysis) from the
example's start for each gauge (ramp, travel at the group velocity, one period) to T, in the reference as in the runs.
--plot draws the tip's excursion and its periodic part against the reference's, over the level's wander and over the
mean lean; runs whose folder name contains 'pf40' are drawn as uniformly fine, 'pf20' as uniformly coarse.
"""
import sys

import numpy as np

T = 1.2                       # wave period, s (the example's default)
GROUP_VELOCITY = 1.053        # c_g at h = 0.2 m, T = 1.2 s, m/s (the example prints it)
PLANT_X = 1.2                 # m
TIP_FROM = 2 * T + PLANT_X / GROUP_VELOCITY + T
LEVEL_FROM = 4.2


def read(path):
    """A CSV of the example: a '# ...' comment line (not in every file), then the column names."""
    with open(path) as f:
        comment = f.readline().startswith('#')
    return np.genfromtxt(path, delimiter=',', names=True, skip_header=1 if comment else 0)


def periodic_half_range(t, y, harmonics=4, degree=2):
    omega = 2 * np.pi / T
    tau = (t - 0.5 * (t[0] + t[-1])) / (0.5 * (t[-1] - t[0]))
    columns = [tau ** p for p in range(degree + 1)]
    for n in range(1, harmonics + 1):
        columns += [np.cos(n * omega * t), np.sin(n * omega * t)]
    c = np.linalg.lstsq(np.column_stack(columns), y, rcond=None)[0]
    phase = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    part = sum(c[degree + 2 * n - 1] * np.cos(n * phase) + c[degree + 2 * n] * np.sin(n * phase)
               for n in range(1, harmonics + 1))
    return 0.5 * (part.max() - part.min())


def read_gauges(run):
    """Times (s), elevations (m, one column per gauge) and gauge positions (m) of DIR/plants/gauges.csv."""
    with open(run + '/plants/gauges.csv') as f:
        lines = [line for line in f if not line.startswith('#')]
    header = lines[0].strip().split(',')
    data = np.array([[float(v) for v in line.split(',')] for line in lines[1:] if line.strip()])
    xs = [float(n[4:]) for n in header if n.startswith('eta_')]
    return data[:, 0], data[:, 1:], np.array(xs)


def zero_crossing_height(t, eta, start, end):
    """Mean height of the complete zero up-crossing waves of eta over [start, end] (analysis/zero_crossing.hpp)."""
    w = (t >= start) & (t <= end)
    e = eta[w] - eta[w].mean()
    up = np.nonzero((e[:-1] < 0) & (e[1:] >= 0))[0] + 1
    return np.mean([e[a:b].max() - e[a:b].min() for a, b in zip(up[:-1], up[1:])])


def heights(run, until=None):
    """(gauge positions, H) of a run, m."""
    if until is None:
        h = read(run + '/plants/wave_heights.csv')
        return np.atleast_1d(h['x']), np.atleast_1d(h['H'])
    t, eta, xs = read_gauges(run)
    return xs, np.array([zero_crossing_height(t, eta[:, j], 2 * T + x / GROUP_VELOCITY + T, until)
                         for j, x in enumerate(xs)])


def analyse(run, reference_heights, until=None):
    """reference_heights: (gauge positions, H) of the reference; the run's gauges at those positions are compared
    (a run may have more gauges, --gauges of the example)."""
    tips = read(run + '/plants/tips.csv')
    end = np.inf if until is None else until + 1e-9
    window = (tips['t'] >= TIP_FROM - 1e-9) & (tips['t'] <= end)
    t, dx, dz, u = tips['t'][window], tips['dx_0'][window], tips['dz_0'][window], tips['u_mid_0'][window]
    gauges = read(run + '/plants/gauges.csv')
    last = gauges['t'][-1] if until is None else min(until, gauges['t'][-1])
    names = [n for n in gauges.dtype.names if n.startswith('eta')]
    means, start = [], LEVEL_FROM
    while start + T <= last + 1e-6:
        w = (gauges['t'] >= start) & (gauges['t'] < start + T)
        means.append([np.nanmean(gauges[n][w]) for n in names])
        start += T / 2
    means = 1e3 * np.array(means)
    k = np.arange(len(means))
    wander = np.mean([np.std(means[:, j] - np.polyval(np.polyfit(k, means[:, j], 1), k))
                      for j in range(means.shape[1])])
    xs, h = heights(run, until)
    x_ref, h_ref = reference_heights
    h = np.array([h[np.argmin(np.abs(xs - x))] if np.min(np.abs(xs - x)) < 1e-6 else np.nan for x in x_ref])
    return dict(H=100 * (h / h_ref - 1), half_peak_to_peak=1e3 * 0.5 * (dx.max() - dx.min()),
                dz=1e3 * 0.5 * (dz.max() - dz.min()),
                periodic=1e3 * periodic_half_range(t, dx), lean=1e3 * dx.mean(), current=1e3 * u.mean(),
                spread=np.mean(means.max(1) - means.min(1)), wander=wander)


def option(argv, name):
    if name not in argv:
        return None, argv
    i = argv.index(name)
    return argv[i + 1], argv[:i] + argv[i + 2:]


def plot(path, rows):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    reference = rows[0][1]
    def group(name):
        return 'fine' if 'pf40' in name else 'coarse' if 'pf20' in name else 'refined'

    groups = {'uniformly fine (h/dp = 40)': ('fine', 'k', 'o'), 'uniformly coarse (h/dp = 20)': ('coarse', 'tab:blue', 's'),
              'refined box (h/dp = 20 / 40)': ('refined', 'tab:red', '^')}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for label, (key, colour, marker) in groups.items():
        chosen = [r for name, r in rows if group(name) == key]
        if not chosen:
            continue
        wander = [r['wander'] for r in chosen]
        hpp = [100 * (r['half_peak_to_peak'] / reference['half_peak_to_peak'] - 1) for r in chosen]
        periodic = [100 * (r['periodic'] / reference['periodic'] - 1) for r in chosen]
        axes[0].scatter(wander, hpp, c=colour, marker=marker, label=label)
        axes[1].scatter([r['lean'] for r in chosen], periodic, c=colour, marker=marker, label=label)
    for ax in axes:
        ax.axhspan(-5, 5, color='0.9', zorder=0)
        ax.grid(alpha=0.3)
    axes[0].set_xlabel('wander of the mean level at the gauges (mm)')
    axes[0].set_ylabel('tip excursion (half peak-to-peak) vs the fine run (%)')
    axes[0].set_title('the tip criterion against the long waves')
    axes[1].set_xlabel('mean lean of the tip (mm; < 0 upstream)')
    axes[1].set_ylabel('periodic part of the tip motion vs the fine run (%)')
    axes[1].set_title('the wave-driven sway against the mean position')
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print('plot:', path)


def main(argv):
    csv_path, argv = option(argv, '--csv')
    plot_path, argv = option(argv, '--plot')
    until, argv = option(argv, '--until')
    until = None if until is None else float(until)
    if len(argv) < 2:
        sys.exit(__doc__)
    reference = argv[0]
    h_ref = heights(reference, until)
    rows = []
    print(f"{'run':30s} {'H vs reference, % (per gauge)':>36s} | {'hpp dx':>6s} {'periodic':>8s} {'lean':>6s} "
          f"{'current':>7s} {'dz':>5s} | {'spread':>6s} {'wander':>6s}")
    for run in argv:
        r = analyse(run, h_ref, until)
        rows.append((run, r))
        print(f"{run:30s} " + ' '.join(f'{e:+8.2f}' for e in r['H']) +
              f" | {r['half_peak_to_peak']:6.2f} {r['periodic']:8.2f} {r['lean']:+6.2f} {r['current']:+7.2f} {r['dz']:5.2f} | "
              f"{r['spread']:6.2f} {r['wander']:6.2f}")
    if csv_path:
        with open(csv_path, 'w') as f:
            window = '' if until is None else f' (every window ends at t = {until} s)'
            f.write('# examples/posidonia_flume/mean_flow.py against ' + reference + window + ': H error per gauge '
                    '(%), tip half peak-to-peak and periodic half range (mm), mean lean (mm), mean current at '
                    'mid-height (mm/s), long-wave spread and wander (mm), tip half peak-to-peak in z (mm)\n')
            f.write('run,' + ','.join(f'H_error_{i}' for i in range(len(h_ref[0]))) +
                    ',tip_half_peak_to_peak,tip_periodic,lean,current,level_spread,level_wander,tip_dz\n')
            for run, r in rows:
                f.write(run + ',' + ','.join(f'{e:.3f}' for e in r['H']) +
                        f",{r['half_peak_to_peak']:.3f},{r['periodic']:.3f},{r['lean']:.3f},{r['current']:.3f},"
                        f"{r['spread']:.3f},{r['wander']:.3f},{r['dz']:.3f}\n")
    if plot_path:
        plot(plot_path, rows)


if __name__ == '__main__':
    main(sys.argv[1:])
