#!/usr/bin/python3
"""Time-mean flow maps of posidonia_flume runs (flow_map.csv, --flow-map-from): where a refined run makes or loses
active water, and how its mean mass flux differs from the uniformly fine run's.

    /usr/bin/python3 examples/posidonia_flume/flow_map.py REFERENCE RUN [RUN ...] --labels fine,paired,... \\
        --box 0.9,1.5,0.13 [--bin 0.01] [--plot map.png] [--csv regions.csv]
    /usr/bin/python3 examples/posidonia_flume/flow_map.py REFERENCE RUN [RUN ...] --windows [--plant 1.2] \\
        [--plot windows.png] [--csv windows.csv]

Prints, per run, the active mass the refinement's passes created in regions around the box (status changes and the
accounts, kg per m width and second), the flux of mass through the box's faces, and the mean horizontal mass flux
(a transport velocity) in the box's lower and upper halves against the reference. Maps: the mean horizontal mass flux
of each run, its difference from the reference, and the sources of active mass, over x 0.7 to 1.7 m.

With --windows (runs with --flow-map-window): per window of each run, the mean kinetic energy upstream of the box, in
it and downstream of it (against the reference's in the same window), the mass per area and the volume fraction inside
and outside the box, and over the pairs of bins that straddle its faces, the mean upwelling over the plant, and the
strength of the mean circulation cells (the rms along the flume of the column-mean vertical flux); --plot draws the
last window's mean flow of each run and the two histories.
"""
import argparse
import glob
import re
import sys

import numpy as np


def read_map(path):
    rows = []
    names = None
    with open(path) as f:
        for line in f:
            if line.startswith('#'):
                continue
            if names is None:
                names = line.strip().split(',')
                continue
            rows.append([float(v) for v in line.split(',')])
    data = np.array(rows)
    x, z = data[:, 0], data[:, 1]
    xs, zs = np.unique(x), np.unique(z)
    grid = {}
    for j, name in enumerate(names):
        g = np.zeros((len(xs), len(zs)))
        g[np.searchsorted(xs, x), np.searchsorted(zs, z)] = data[:, j]
        grid[name] = g
    return xs, zs, grid


def coarsen(xs, zs, grid, factor):
    """Sums of `factor` x `factor` bins: counts and sources add, per-area means average."""
    nx, nz = len(xs) // factor, len(zs) // factor
    out = {}
    for name, g in grid.items():
        g = g[:nx * factor, :nz * factor].reshape(nx, factor, nz, factor)
        if name == 'fine_mass_ratio':
            w = grid['active_fine'][:nx * factor, :nz * factor].reshape(nx, factor, nz, factor)
            s = w.sum(axis=(1, 3))
            out[name] = np.where(s > 0, (g * w).sum(axis=(1, 3)) / np.maximum(s, 1e-300), 0)
        elif name in ('x', 'z'):
            out[name] = g.mean(axis=(1, 3))
        elif name.startswith('active') or name.startswith('passive'):
            out[name] = g.sum(axis=(1, 3))
        else:
            out[name] = g.mean(axis=(1, 3))
    return out['x'][:, 0], out['z'][0, :], out


def region_sum(xs, zs, field, bin_area, x0, x1, z0, z1):
    """Integral of a per-area field over the bins whose centres lie in [x0, x1) x [z0, z1)."""
    mx = (xs >= x0) & (xs < x1)
    mz = (zs >= z0) & (zs < z1)
    return field[np.ix_(mx, mz)].sum() * bin_area


def window_files(run):
    """The window maps of a run, in order: its plants run's, or its empty flume's if it has no plants run."""
    for case in ('plants', 'empty'):
        files = sorted(glob.glob(f'{run}/{case}/flow_map_window*.csv'),
                       key=lambda f: int(re.search(r'window(\d+)\.csv$', f).group(1)))
        if files:
            return files
    sys.exit(f'flow_map.py: no {run}/plants/ or {run}/empty/flow_map_window*.csv (run with --flow-map-window)')


def map_header(path):
    """(start time s, samples, tracked time s) from a flow map's first line."""
    with open(path) as f:
        line = f.readline()
    start = re.search(r'from t = ([0-9.eE+-]+) s', line)
    counts = re.search(r'\((\d+) samples, ([0-9.eE+-]+) s tracked\)', line)
    return (float(start.group(1)) if start else float('nan'), int(counts.group(1)) if counts else 0,
            float(counts.group(2)) if counts else float('nan'))


def window_start(path):
    return map_header(path)[0]


def check_windows(runs, labels, tolerance):
    """Exit 1 unless, in every run, the window maps add up to the whole-record map: the sampled fields weighted by
    their windows' samples, the sources by their windows' tracked time, each to within `tolerance` of the field's
    largest magnitude over the map."""
    sampled = ['active_coarse', 'active_fine', 'passive_coarse', 'passive_fine', 'mass_per_area', 'volume_fraction',
               'flux_x', 'flux_z', 'kinetic_energy']
    tracked = ['status_source', 'account_source']
    failed = False
    for run, label in zip(runs, labels):
        files = window_files(run)
        whole_path = files[0].rsplit('/', 1)[0] + '/flow_map.csv'
        _, whole_samples, whole_time = map_header(whole_path)
        _, _, whole = read_map(whole_path)
        sums = {name: np.zeros_like(whole[name]) for name in sampled + tracked}
        samples, duration = 0, 0.0
        for path in files:
            _, n, t = map_header(path)
            _, _, g = read_map(path)
            for name in sampled:
                sums[name] += n * g[name]
            for name in tracked:
                sums[name] += t * g[name]
            samples, duration = samples + n, duration + t
        worst = 0.0
        for name in sampled + tracked:
            weight = whole_samples if name in sampled else whole_time
            scale = np.abs(whole[name]).max()
            if scale > 0:
                worst = max(worst, np.abs(sums[name] - weight * whole[name]).max() / (weight * scale))
        ok = samples == whole_samples and abs(duration - whole_time) <= tolerance * whole_time and worst <= tolerance
        failed = failed or not ok
        print(f'{label}: {len(files)} windows, {samples} samples ({whole_samples} in the whole map), {duration:.9g} s '
              f'tracked ({whole_time:.9g}); largest difference of the summed windows from the whole map {worst:.2e} of '
              f'the field\'s largest magnitude (tolerance {tolerance:g}) ' + ('PASS' if ok else 'FAIL'))
    sys.exit(1 if failed else 0)


def window_table(runs, labels, box, plant, csv_path, plot_path):
    """Per window: kinetic energy by region (against the reference), mass and volume inside and outside the box, and
    the mean vertical transport over the plant."""
    bx0, bx1, btop = box
    below = btop - 0.02  # the box's lower part, clear of its top face
    regions = [('upstream', 0.5, bx0 - 0.05, 0, 1), ('box', bx0 + 0.05, bx1 - 0.05, 0, 1),
               ('downstream', bx1 + 0.05, 1.9, 0, 1)]
    columns = []
    per_run = []
    last_maps = []
    for run in runs:
        rows = []
        for path in window_files(run):
            xs, zs, g = read_map(path)
            area = (xs[1] - xs[0]) * (zs[1] - zs[0])
            row = {'start': window_start(path)}
            for name, x0, x1, z0, z1 in regions:
                row[f'ke_{name}'] = region_sum(xs, zs, g['kinetic_energy'], area, x0, x1, z0, z1)

            def mean(field, x0, x1, z0, z1):
                return region_sum(xs, zs, g[field], area, x0, x1, z0, z1) / region_sum(
                    xs, zs, np.ones_like(g[field]), area, x0, x1, z0, z1)

            row['mass_box'] = mean('mass_per_area', bx0 + 0.05, bx1 - 0.05, 0, below)
            row['mass_out'] = 0.5 * (mean('mass_per_area', 0.6, bx0 - 0.05, 0, below) +
                                     mean('mass_per_area', bx1 + 0.05, 1.8, 0, below))
            row['vf_box'] = mean('volume_fraction', bx0 + 0.05, bx1 - 0.05, 0, below)
            row['vf_out'] = 0.5 * (mean('volume_fraction', 0.6, bx0 - 0.05, 0, below) +
                                   mean('volume_fraction', bx1 + 0.05, 1.8, 0, below))
            row['vf_faces'] = 0.5 * (mean('volume_fraction', bx0 - 0.01, bx0 + 0.01, 0, below) +
                                     mean('volume_fraction', bx1 - 0.01, bx1 + 0.01, 0, below))
            # the mean upwelling over the plant: flux_z over plant +- 5 cm, 5 to 15 cm above the bed
            row['upwelling'] = mean('flux_z', plant - 0.05, plant + 0.05, 0.05, 0.15)
            # the strength of the mean circulation cells along the flume: the rms over 1 cm columns from 0.6 to 1.8 m of
            # the vertical mass flux averaged over 2 to 17 cm above the bed (the sampling noise of single particles
            # averages out over the column)
            cx, cz, cg = coarsen(xs, zs, g, max(1, int(round(0.01 / (xs[1] - xs[0])))))
            column = cg['flux_z'][:, (cz > 0.02) & (cz < 0.17)].mean(axis=1)
            row['circulation'] = np.sqrt(np.mean(column[(cx > 0.6) & (cx < 1.8)] ** 2))
            rows.append(row)
            last = (xs, zs, g)
        per_run.append(rows)
        last_maps.append(last)
        columns = list(rows[0].keys())
    ref = per_run[0]
    print('kinetic energy (time-mean, mJ per m width) upstream / in / downstream of the box, and against the '
          'reference; mass per area (kg/m^3) and volume fraction below the box top - 2 cm, in the box / outside / over its faces:')
    for rows, label in zip(per_run, labels):
        print(f'  {label}:')
        for k, row in enumerate(rows):
            rel = [row[f'ke_{n}'] / ref[k][f'ke_{n}'] - 1 if k < len(ref) else float('nan') for n, *_ in regions]
            ke = ' / '.join(f'{1e3 * row[f"ke_{n}"]:.3f}' for n, *_ in regions)
            against = ' / '.join(f'{100 * v:+.2f}' for v in rel)
            print(f'    from {row["start"]:6.2f} s: KE {ke} mJ/m ({against} %); mass {row["mass_box"]:.2f} / '
                  f'{row["mass_out"]:.2f}; volume fraction {row["vf_box"]:.4f} / {row["vf_out"]:.4f} / '
                  f'{row["vf_faces"]:.4f}; upwelling over the plant {1e3 * row["upwelling"]:+.1f} mm/s; circulation '
                  f'{1e3 * row["circulation"]:.1f} mm/s')
    if csv_path:
        with open(csv_path, 'w') as f:
            f.write('# per window of the flow maps (flow_map.py --windows): time-mean kinetic energy upstream of '
                    'the box, in it and downstream of it (J per m width), mass per area (kg/m^3) and volume fraction in '
                    'the box and outside it below its top - 2 cm, and the volume fraction over the bins straddling its '
                    'side faces; the mean vertical mass flux over the plant +- 5 cm, 5 to 15 cm above the bed (m/s); the '
                    'circulation: the rms along x (0.6-1.8 m, 1 cm columns) of the vertical mass flux averaged over '
                    '2-17 cm above the bed (m/s)\n')
            f.write('run,' + ','.join(columns) + '\n')
            for rows, label in zip(per_run, labels):
                for row in rows:
                    f.write(label + ',' + ','.join(f'{row[c]:.6g}' for c in columns) + '\n')
    if plot_path:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        n = len(runs)
        fig = plt.figure(figsize=(15, 2.4 * n + 2.6))
        grid = fig.add_gridspec(n + 1, 2)
        for i, ((xs, zs, g), label, rows) in enumerate(zip(last_maps, labels, per_run)):
            xs, zs, g = coarsen(xs, zs, g, 4)
            mx, mz = (xs > 0.7) & (xs < 1.75), zs < 0.22
            ext = [xs[mx][0] - 0.005, xs[mx][-1] + 0.005, 0, zs[mz][-1] + 0.005]
            for col, name in enumerate(('flux_x', 'flux_z')):
                ax = fig.add_subplot(grid[i, col])
                im = ax.imshow(1e3 * g[name][np.ix_(mx, mz)].T, origin='lower', extent=ext, aspect='auto',
                               cmap='RdBu_r', vmin=-60, vmax=60)
                ax.add_patch(plt.Rectangle((bx0, 0), bx1 - bx0, btop, fill=False, ls='--', lw=0.8))
                ax.axvline(plant, color='k', lw=0.6, ls=':')
                component = 'u' if col == 0 else 'w'
                ax.set_title(f'{label}: mean {component} (mass flux), mm/s, from {rows[-1]["start"]:.2f} s', fontsize=9)
                ax.set_ylabel('z (m)')
                fig.colorbar(im, ax=ax, fraction=0.03)
        for col, (name, title) in enumerate((('upwelling', 'mean upwelling over the plant (mm/s)'),
                                             ('circulation', 'circulation: rms of the column-mean w (mm/s)'))):
            ax = fig.add_subplot(grid[n, col])
            for rows, label in zip(per_run, labels):
                ax.plot([r['start'] for r in rows], [1e3 * r[name] for r in rows], 'o-', label=label)
            ax.set_xlabel('window start (s)')
            ax.set_ylabel(title, fontsize=9)
            if name == 'circulation':
                ax.set_yscale('log')
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(plot_path, dpi=110)
        print(f'plot: {plot_path}')


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('runs', nargs='+', help='run folders (the first is the reference); their plants/flow_map.csv')
    ap.add_argument('--labels', default='', help='comma-separated labels')
    ap.add_argument('--box', default='0.9,1.5,0.13', help='box x0,x1,top (m)')
    ap.add_argument('--bin', type=float, default=0.01, help='bin of the maps and sums, m (a multiple of 2.5 mm)')
    ap.add_argument('--plot', default='', help='PNG of the maps')
    ap.add_argument('--csv', default='', help='CSV of the region sums')
    ap.add_argument('--windows', action='store_true',
                    help='compare the runs window by window (their flow_map_window*.csv, --flow-map-window)')
    ap.add_argument('--plant', type=float, default=1.2, help='x of the plant (m), for --windows')
    ap.add_argument('--check-windows', type=float, default=0, metavar='TOL',
                    help='exit 1 unless, in every run, the window maps add up to the whole-record map (sampled fields '
                         'weighted by samples, sources by tracked time) within TOL of each field\'s largest magnitude')
    ap.add_argument('--check-balance', type=float, default=0, metavar='TOL',
                    help='exit 1 unless, in every run, the status and account sources summed over the map cancel to '
                         'within TOL times the sum of the status sources\' magnitudes (a refined run with the mass '
                         'account on conserves the active mass at every pass)')
    a = ap.parse_args()
    labels = a.labels.split(',') if a.labels else [r.rstrip('/').split('/')[-1] for r in a.runs]
    if len(labels) != len(a.runs):
        sys.exit('flow_map.py: --labels needs one label per run')
    bx0, bx1, btop = (float(v) for v in a.box.split(','))
    if a.check_windows > 0:
        check_windows(a.runs, labels, a.check_windows)
    if a.windows:
        window_table(a.runs, labels, (bx0, bx1, btop), a.plant, a.csv, a.plot)
        return
    if a.check_balance > 0:
        failed = False
        for r, label in zip(a.runs, labels):
            xs, zs, g = read_map(f'{r}/plants/flow_map.csv')
            area = (xs[1] - xs[0]) * (zs[1] - zs[0])
            net = (g['status_source'] + g['account_source']).sum() * area
            scale = np.abs(g['status_source']).sum() * area
            ok = scale > 0 and abs(net) <= a.check_balance * scale
            failed = failed or not ok
            print(f'{label}: sources of active mass over the map: net {net:+.3e} kg/(m s), status changes\' magnitude '
                  f'{scale:.3e} kg/(m s): ratio {abs(net) / scale if scale > 0 else float("nan"):.2e} '
                  f'(tolerance {a.check_balance:g}) ' + ('PASS' if ok else 'FAIL' if scale > 0 else
                                                        'FAIL (no status change recorded: nothing checked)'))
        sys.exit(1 if failed else 0)
    maps = []
    for r in a.runs:
        xs, zs, g = read_map(f'{r}/plants/flow_map.csv')
        factor = max(1, int(round(a.bin / (xs[1] - xs[0]))))
        maps.append(coarsen(xs, zs, g, factor))
    bin_area = a.bin * a.bin
    rows = []
    half = btop / 2
    # disjoint regions (the last is the whole map): the top band takes the box's top face, the columns its sides
    band = min(0.05, half)
    regions = [
        ('upstream corner (x0 +- 5 cm, below top/2)', bx0 - 0.05, bx0 + 0.05, 0, half),
        ('upstream edge upper (x0 +- 5 cm, top/2 to top - 5 cm)', bx0 - 0.05, bx0 + 0.05, half, btop - band),
        ('box interior lower', bx0 + 0.05, bx1 - 0.05, 0, half),
        ('box interior upper (to top - 5 cm)', bx0 + 0.05, bx1 - 0.05, half, btop - band),
        ('box top band (top +- 5 cm)', bx0 - 0.05, bx1 + 0.05, btop - band, btop + band),
        ('downstream corner (x1 +- 5 cm, below top/2)', bx1 - 0.05, bx1 + 0.05, 0, half),
        ('downstream edge upper (x1 +- 5 cm, top/2 to top - 5 cm)', bx1 - 0.05, bx1 + 0.05, half, btop - band),
        ('everything', -1, 10, -1, 10),
    ]
    print('active mass created per second (kg/(m s)) by status changes / accounts / both:')
    for (xs, zs, g), label in zip(maps, labels):
        print(f'  {label}:')
        for name, x0, x1, z0, z1 in regions:
            s = region_sum(xs, zs, g['status_source'], bin_area, x0, x1, z0, z1)
            c = region_sum(xs, zs, g['account_source'], bin_area, x0, x1, z0, z1)
            print(f'    {name:48s} {s:+.4e} / {c:+.4e} / {s + c:+.4e}')
            rows.append((label, name, s, c))
    print('mean horizontal mass flux sum m u / (rho0 A), mm/s (averaged over the region):')
    ref = maps[0]
    for (xs, zs, g), label in zip(maps, labels):
        out = []
        for name, x0, x1, z0, z1 in regions[:7]:
            area = region_sum(xs, zs, np.ones_like(g['flux_x']), bin_area, x0, x1, z0, z1)
            out.append(region_sum(xs, zs, g['flux_x'], bin_area, x0, x1, z0, z1) / area * 1e3)
        print(f'  {label:14s} ' + ' '.join(f'{v:+7.2f}' for v in out))
    # the column transport below the box top: sum over z of flux_x dz, along x (m^2/s per m width)
    print('mean transport below the box top, integral of flux_x over 0 < z < top, mm^2/s, at x =')
    xs0 = maps[0][0]
    probes = [bx0 - 0.1, bx0 - 0.03, bx0 + 0.03, bx0 + 0.1, 0.5 * (bx0 + bx1), bx1 - 0.1, bx1 - 0.03, bx1 + 0.03,
              bx1 + 0.1]
    print('  ' + ' '.join(f'{x:8.3f}' for x in probes))
    for (xs, zs, g), label in zip(maps, labels):
        vals = []
        for x in probes:
            i = int(np.argmin(np.abs(xs - x)))
            mz = zs < btop
            vals.append(g['flux_x'][i, mz].sum() * a.bin * 1e6)
        print(f'  {label:14s}' + ' '.join(f'{v:+8.1f}' for v in vals))
    print('mean transport over the whole depth (a source between two stations steps it), mm^2/s, at the same x:')
    for (xs, zs, g), label in zip(maps, labels):
        vals = [g['flux_x'][int(np.argmin(np.abs(xs - x))), :].sum() * a.bin * 1e6 for x in probes]
        print(f'  {label:14s}' + ' '.join(f'{v:+8.1f}' for v in vals))
    if a.csv:
        with open(a.csv, 'w') as f:
            f.write('# active mass created per second by the refinement passes in regions around the box '
                    '(flow_map.py); kg/(m s)\n')
            f.write('run,region,status_source,account_source\n')
            for label, name, s, c in rows:
                f.write(f'{label},"{name}",{s:.6e},{c:.6e}\n')
    if a.plot:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        n = len(maps)
        fig, axes = plt.subplots(n, 3, figsize=(15, 2.6 * n), squeeze=False, sharex=True, sharey=True)
        for row, ((xs, zs, g), label) in enumerate(zip(maps, labels)):
            mx = (xs > 0.7) & (xs < 1.7)
            mz = zs < 0.2
            ext = [xs[mx][0] - a.bin / 2, xs[mx][-1] + a.bin / 2, 0, zs[mz][-1] + a.bin / 2]
            panels = [(g['flux_x'] * 1e3, f'{label}: mean mass flux u, mm/s', 30),
                      ((g['flux_x'] - ref[2]['flux_x']) * 1e3, f'{label} - {labels[0]}, mm/s', 30),
                      (g['status_source'] + g['account_source'], f'{label}: source of active mass, kg/(m^3 s)', None)]
            for col, (field, title, lim) in enumerate(panels):
                f = field[np.ix_(mx, mz)].T
                if lim is None:
                    lim = max(np.percentile(np.abs(f), 99.5), 1e-12)
                im = axes[row, col].imshow(f, origin='lower', extent=ext, aspect='auto', cmap='RdBu_r', vmin=-lim,
                                           vmax=lim)
                axes[row, col].set_title(title, fontsize=9)
                axes[row, col].add_patch(plt.Rectangle((bx0, 0), bx1 - bx0, btop, fill=False, ls='--', lw=0.8))
                fig.colorbar(im, ax=axes[row, col], fraction=0.03)
        for ax in axes[-1]:
            ax.set_xlabel('x (m)')
        for ax in axes[:, 0]:
            ax.set_ylabel('z (m)')
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f'plot: {a.plot}')


if __name__ == '__main__':
    main()
