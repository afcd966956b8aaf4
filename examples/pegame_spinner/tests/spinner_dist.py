"""Make the example distribution visible without installing it: a hand-written dist-info
with its entry points, which is what `pip install examples/pegame_spinner` writes."""

from __future__ import annotations

from pathlib import Path

#: examples/pegame_spinner, the directory that holds the import package ``spinner``
EXAMPLE = Path(__file__).resolve().parents[1]


def write_dist_info(site: Path) -> Path:
    """Write pegame_spinner's dist-info into ``site`` (a directory to put on the path)."""
    info = site / "pegame_spinner-0.1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: pegame-spinner\nVersion: 0.1.0\n")
    (info / "entry_points.txt").write_text(
        "[pegame.pursuers]\nspinner = spinner:Spinner\n\n[pegame.configs]\nspinner = spinner.conf\n"
    )
    return site
