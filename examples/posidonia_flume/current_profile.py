"""The mean current along the flume, at the blade's four profile heights: where a refinement box changes it.

Usage: /usr/bin/python3 examples/posidonia_flume/current_profile.py RUN_DIR... [--labels A,B,...] [--box X0,X1]
                                                                            [--csv FILE] [--plot PNG]

Reads DIR/plants/currents.csv (posidonia_flume writes the active fluid's Eulerian horizontal velocity every 0.1 m
from x = 0.5 to 1.9 m at l/8, 3l/8, 5l/8 and 7l/8 above the bed) and averages it over whole wave periods from the time
the example's tip analysis starts (the ramp, the wave's travel to the plant and one period) to the end of the record.
Prints the mean current (mm/s) at every x and height for every run, and its means over the stretches upstream of, in
and downstream of the box (default 0.9-1.5 m) with their standard errors; --csv writes the point means (run, x, z, u_mean), --plot draws
it against x, one panel per height, with the box (--box, m) shaded.
"""
import sys

import numpy as np

T = 1.2                       # wave period, s (the example's default)
GROUP_VELOCITY = 1.053        # c_g at h = 0.2 m, T = 1.2 s, m/s (the example prints it)
PLANT_X = 1.2                 # m
WINDOW_FROM = 2 * T + PLANT_X / GROUP_VELOCITY + T


def read(path):
    with open(path) as f:
        comment = f.readline().startswith('#')
    return np.genfromtxt(path, delimiter=',', names=True, deletechars='', skip_header=1 if comment else 0)


def columns(data):
    """{(x, z): column name} from the names u_x{x}_z{z} (x, z in m)."""
    out = {}
    for name in data.dtype.names[1:]:
        x_part, z_part = name[len('u_x'):].split('_z')
        out[(float(x_part), float(z_part))] = name
    return out


def mean_current(run):
    data = read(run + '/plants/currents.csv')
    t = data['t']
    periods = int(np.floor((t[-1] - WINDOW_FROM) / T + 1e-9))
    if periods < 1:
        raise SystemExit(f'{run}: the record ends before one full period of the analysis window')
    window = (t >= WINDOW_FROM - 1e-9) & (t < WINDOW_FROM + periods * T - 1e-9)
    return {key: 1e3 * np.mean(data[name][window]) for key, name in columns(data).items()}, periods


def option(argv, name):
    if name not in argv:
        return None, argv
    i = argv.index(name)
    return argv[i + 1], argv[:i] + argv[i + 2:]


def main(argv):
    csv_path, argv = option(argv, '--csv')
    png_path, argv = option(argv, '--plot')
    labels, argv = option(argv, '--labels')
    box, argv = option(argv, '--box')
    runs = argv
    if not runs:
        raise SystemExit(__doc__)
    labels = labels.split(',') if labels else runs
    if len(labels) != len(runs):
        raise SystemExit('--labels: one label per run')
    results = [mean_current(r) for r in runs]
    xs = sorted({x for x, _ in results[0][0]})
    zs = sorted({z for _, z in results[0][0]})
    for z in zs:
        print(f'mean current at z = {1e3 * z:.0f} mm (mm/s)')
        print('  x (m) ' + ''.join(f'{label[:14]:>15}' for label in labels))
        for x in xs:
            print(f'  {x:5.2f} ' + ''.join(f'{r[0][(x, z)]:15.2f}' for r in results))
    # Along x the point means scatter by 1-2 mm/s (particle noise over a few periods): means over stretches of the
    # flume, +- the standard error of the stretch's points.
    x0, x1 = (float(v) for v in box.split(',')) if box else (0.9, 1.5)
    stretches = [('upstream', lambda x: x < x0 - 1e-9), ('box', lambda x: x0 - 1e-9 <= x <= x1 + 1e-9),
                 ('downstream', lambda x: x > x1 + 1e-9)]
    print(f'mean over stretches of x (box {x0:.2f}-{x1:.2f} m), mm/s, +- standard error')
    for z in zs:
        for name, inside in stretches:
            cells = []
            for r in results:
                v = np.array([r[0][(x, z)] for x in xs if inside(x)])
                cells.append(f'{v.mean():+7.2f} +- {v.std(ddof=1) / np.sqrt(len(v)):4.2f}' if len(v) > 1 else '-')
            print(f'  z = {1e3 * z:3.0f} mm {name:>10} ' + ''.join(f'{c:>17}' for c in cells))
    for label, (_, periods) in zip(labels, results):
        print(f'{label}: averaged over {periods} periods from t = {WINDOW_FROM:.2f} s')
    if csv_path:
        with open(csv_path, 'w') as f:
            f.write('# mean current along the flume, mm/s, over whole periods from t = '
                    f'{WINDOW_FROM:.3f} s (examples/posidonia_flume/current_profile.py)\n')
            f.write('run,x,z,u_mean\n')
            for label, (u, _) in zip(labels, results):
                for (x, z), value in sorted(u.items()):
                    f.write(f'{label},{x:.2f},{z:.4f},{value:.4f}\n')
    if png_path:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(zs), figsize=(4 * len(zs), 3.6), sharey=True)
        for ax, z in zip(axes, zs):
            for label, (u, _) in zip(labels, results):
                ax.plot(xs, [u[(x, z)] for x in xs], marker='o', ms=3, label=label)
            if box:
                x0, x1 = (float(v) for v in box.split(','))
                ax.axvspan(x0, x1, color='0.9', zorder=0)
            ax.axvline(PLANT_X, color='g', lw=0.8, ls=':')
            ax.axhline(0, color='k', lw=0.5)
            ax.set_title(f'{1e3 * z:.0f} mm above the bed')
            ax.set_xlabel('x (m)')
        axes[0].set_ylabel('mean current (mm/s)')
        axes[0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(png_path, dpi=120)
        print(f'plot: {png_path}')


if __name__ == '__main__':
    main(sys.argv[1:])
