"""Which outputs a run writes: the formats the user chooses, and the files each one is.

    attitude run S.toml --out D --formats csv,parquet,aem,plots,report

- ``csv``: ``timeseries.csv``, the time series as text (17 significant digits at most:
  every number reads back as the same double);
- ``parquet``: ``timeseries.parquet``, the same columns in Apache Parquet, for series
  too big for CSV, with the frames, units, time scale and quaternion convention in
  its schema (:mod:`attitude.outputs.parquet`);
- ``aem``: ``attitude.aem``, a CCSDS AEM 2.0 sampled for a stated interpolation
  accuracy (:mod:`attitude.outputs.aem_sampling`);
- ``plots``: the PNG figures; ``report``: ``report.html``, the page that gathers them.

``summary.json`` is always written, and ``intervals.csv`` whenever the scenario has a
``[pointing]`` section: both are small, and they hold the results.  The default is
today's set, :data:`DEFAULT_FORMATS`: ``csv,aem,plots,report``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from attitude.base.errors import InputError
from attitude.outputs.aem_sampling import DEFAULT_TOLERANCE_RAD, check_tolerance

__all__ = [
    "DEFAULT_FORMATS",
    "FORMATS",
    "OUTPUT_NAMES",
    "PLOT_NAMES",
    "OutputChoice",
    "parse_formats",
]

PLOT_NAMES = ("angular_velocity.png", "polhode.png", "sun_angles.png", "eclipse.png")
# Format -> the files it may write.
FILES = {
    "csv": ("timeseries.csv",),
    "parquet": ("timeseries.parquet",),
    "aem": ("attitude.aem",),
    "plots": PLOT_NAMES,
    "report": ("report.html",),
}
FORMATS = tuple(FILES)
DEFAULT_FORMATS = ("csv", "aem", "plots", "report")
# Every file a run may write (the output folder's manifest lists those it wrote).
OUTPUT_NAMES = ("summary.json", "intervals.csv", *(name for f in FILES.values() for name in f))


def parse_formats(text: str | list | tuple, name: str = "--formats") -> tuple[str, ...]:
    """The formats named in ``text`` (``"csv,aem"``, or a list of names), in the order of
    :data:`FORMATS`; :class:`InputError` naming ``name`` for anything else."""
    if isinstance(text, str):
        items = [item.strip().lower() for item in text.split(",")]
    elif isinstance(text, list | tuple) and all(isinstance(item, str) for item in text):
        items = [item.strip().lower() for item in text]
    else:
        raise InputError(f"expected format names, got {text!r}", key=name, value=text)
    items = [item for item in items if item]
    if not items:
        raise InputError(f"give one or more of {', '.join(FORMATS)}", key=name, value=text)
    unknown = [item for item in items if item not in FILES]
    if unknown:
        shown = repr(unknown[0])
        shown = shown if len(shown) <= 42 else shown[:40] + "...'"
        raise InputError(
            f"unknown format {shown}: choose from {', '.join(FORMATS)} "
            f"(comma-separated, e.g. {','.join(DEFAULT_FORMATS)})",
            key=name,
            value=unknown[0],
        )
    return tuple(f for f in FORMATS if f in items)


@dataclass(frozen=True)
class OutputChoice:
    """What a run writes: its formats, and the accuracy its AEM is sampled for."""

    formats: tuple[str, ...] = DEFAULT_FORMATS
    aem_tolerance_rad: float = DEFAULT_TOLERANCE_RAD
    # Where the tolerance was given, for the messages that concern it.
    tolerance_key: str = field(default="output.aem_tolerance", compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "formats", parse_formats(self.formats, "formats"))
        check_tolerance(self.aem_tolerance_rad, self.tolerance_key)

    def __contains__(self, item: str) -> bool:
        return item in self.formats
