"""What every tool shares, standard library only: the one-line failure and atomic writes.

Every failure a user can cause (missing file, wrong channels, bad glTF, a bad option) raises
ToolError with a one-line message; each tool's main() runs under run_main(), which turns it
into that line on stderr and a non-zero exit. Files are written to a temporary name beside
their destination and renamed over it, so an interrupted tool leaves no half-written file.
"""

import os
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class ToolError(Exception):
    """A user-facing failure: one line, no traceback."""


def run_main(tool, main):
    """Runs main(); ToolError and OS errors become one line on stderr and exit code 1."""
    try:
        sys.exit(main() or 0)
    except ToolError as e:
        print(f"{tool}: {e}", file=sys.stderr)
        sys.exit(1)
    except OSError as e:
        print(f"{tool}: {e.filename}: {e.strerror}" if e.filename else f"{tool}: {e}",
              file=sys.stderr)
        sys.exit(1)
    except KeyboardInterrupt:
        print(f"{tool}: interrupted", file=sys.stderr)
        sys.exit(130)


def parse_resolution(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise ToolError(f"--resolution {text}: expected WxH, e.g. 64x64") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ToolError(f"--resolution {text}: each side must be 1 .. 16384")
    return w, h


def temp_beside(path, suffix):
    """A fresh temporary file name in path's folder (so a rename over path is atomic), with
    the permissions a newly created file gets (mkstemp's are owner-only)."""
    folder = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=suffix,
                                   dir=folder)
    except OSError as e:
        raise ToolError(f"{path}: cannot write ({e.strerror})") from None
    os.close(fd)
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(tmp, 0o666 & ~mask)
    return tmp


def replace_atomically(path, suffix, write):
    """Calls write(tmp) on a temporary name beside path, then renames it over path; the
    temporary file is removed if write fails."""
    tmp = temp_beside(path, suffix)
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def write_text(path, text):
    """Writes text to path, atomically."""
    def write(tmp):
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
    replace_atomically(path, ".tmp", write)


def use_agg():
    """Selects matplotlib's file-only backend (no display needed) and returns pyplot."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_figure(fig, path, dpi=100):
    """Saves a matplotlib figure as PNG, atomically, and closes it."""
    import matplotlib.pyplot as plt
    try:
        replace_atomically(path, ".png", lambda tmp: fig.savefig(tmp, format="png", dpi=dpi))
    finally:
        plt.close(fig)


def save_png(path, rgb):
    """Saves an (h, w, 3) array of values in [0, 1] as a PNG, pixel for pixel, atomically."""
    import matplotlib.pyplot as plt
    replace_atomically(path, ".png", lambda tmp: plt.imsave(tmp, rgb, format="png"))
