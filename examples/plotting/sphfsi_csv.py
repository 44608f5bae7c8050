"""Reading sphfsi's CSV output in the example plot scripts.

sphfsi writes CSV files (io/csv.hpp) with '#' comment lines (the source and units), one header row and numeric
rows. The plot scripts import this module through their parent folder:

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
    from sphfsi_csv import read_columns
"""
import csv


def read_columns(path):
    """The numeric columns of an sphfsi CSV file, as {header name: list of floats}."""
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    header, data = rows[0], rows[1:]
    return {name: [float(r[i]) for r in data] for i, name in enumerate(header)}
