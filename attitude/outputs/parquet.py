"""``timeseries.parquet``: the time series in Apache Parquet, a row group per chunk.

CSV stops being practical around a gigabyte (a 30-day run at 1 s writes 1.7 GB of
it); Parquet is the columnar format the PyData world reads (pandas, polars, DuckDB,
Spark, Arrow itself), compressed (zstd) and typed.  The file holds the same columns as
``timeseries.csv``, in the same units, plus an exact time column:

- ``time_<scale>``: the ISO 8601 epoch text in the scenario's time scale, to 1 ns,
  exactly as in the CSV.  In UTC a sample inside a leap second reads
  ``…T23:59:60.…``, as UTC writes it.
- ``tt_ns``: int64, TT nanoseconds since the scenario epoch (``epoch_tt`` in the
  metadata), the uniform count the solver uses: exact, monotonic, and never
  ambiguous, unlike a POSIX timestamp, which has no leap seconds (pandas' and
  Arrow's ``timestamp`` types are POSIX: 2016-12-31T23:59:60.5 UTC has no value in
  them, and a UTC "elapsed time" taken from them is off by one second across a leap
  second).  This is why no ``timestamp`` column is written: convert with astropy,
  ``Time(epoch_tt, scale="tt") + TimeDelta(tt_ns * 1e-9, format="sec")``, or use
  the texts.  int64 nanoseconds count 292 years; a longer span is refused.
- ``t_s``: the same instant as a float (TT seconds since the epoch), as in the CSV.

The schema's key-value metadata (keys ``attitude.*``) states the epoch, the time
scale, the frames, the units and the quaternion convention; each field's metadata
gives its ``unit`` and ``description``.  :class:`ParquetWriter` writes a row group per
chunk it is given, so memory stays that of one chunk.
"""

from __future__ import annotations

import json
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.outputs.csv import Column, arrow_texts

__all__ = ["MAX_SPAN_S", "ParquetWriter", "check_span", "unit_of"]

# int64 nanoseconds: ±9.2e18 ns, 292 years.
MAX_SPAN_S = float(np.iinfo(np.int64).max) / 1e9
COMPRESSION = "zstd"

# Column-name endings -> units (the CSV's naming convention: the unit ends the name).
_UNITS = (
    ("_rad_s", "rad/s"),
    ("_N_m_s", "N m s"),
    ("_deg", "deg"),
    ("_J", "J"),
    ("_s", "s"),
)


def unit_of(name: str) -> str:
    """The unit a column's name ends with ("1" for a pure number: quaternions, cosines,
    fractions, flags, indices)."""
    for ending, unit in _UNITS:
        if name.endswith(ending):
            return unit
    return "1"


def check_span(start_s: float, stop_s: float, name: str = "parquet") -> None:
    """Refuse a span that int64 TT nanoseconds since the epoch cannot count."""
    if max(abs(start_s), abs(stop_s)) >= MAX_SPAN_S:
        raise InputError(
            f"the span reaches {stop_s / (365.25 * 86400):.0f} years from the epoch; "
            "the tt_ns column (int64 nanoseconds) counts 292: choose other --formats "
            "or a shorter span",
            key=name,
        )


class ParquetWriter:
    """``timeseries.parquet`` written a row group per :meth:`write` call.

    ``metadata``: the schema's key-value metadata (keys are prefixed ``attitude.``;
    values that are not text are written as JSON).  The schema is fixed by the first
    chunk.  A context manager: the file is finished (its footer written) on exit; after
    an error, as far as it can be, for the caller to remove.
    """

    def __init__(
        self, path: Path, time_label: str, metadata: dict[str, Any], time_description: str
    ) -> None:
        self.path = Path(path)
        self.time_label = time_label
        self._metadata = {
            f"attitude.{key}": value if isinstance(value, str) else json.dumps(value)
            for key, value in metadata.items()
        }
        self._time_description = time_description
        self._writer = None
        self._schema = None

    def _make_schema(self, columns: list[Column]):
        import pyarrow as pa

        def field(name, kind, unit, description):
            return pa.field(
                name, kind, nullable=False, metadata={"unit": unit, "description": description}
            )

        fields = [
            field(self.time_label, pa.string(), "ISO 8601", self._time_description),
            field("tt_ns", pa.int64(), "ns", "TT nanoseconds since the scenario epoch, exact"),
        ]
        for c in columns:  # the CSV's order; the segment index as an integer
            kind = pa.int32() if c.name == "segment" else pa.float64()
            fields.append(field(c.name, kind, unit_of(c.name), c.description))
        return pa.schema(fields, metadata=self._metadata)

    def write(self, epochs: NDArray, seconds: NDArray[np.float64], columns: list[Column]) -> None:
        """Append a row group: one row per epoch (ISO texts; ``seconds``: TT s since the
        epoch, for ``tt_ns``), then each column's values."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        if self._schema is None:
            self._schema = self._make_schema(columns)
            self._writer = pq.ParquetWriter(
                self.path, self._schema, compression=COMPRESSION, write_statistics=True
            )
        by_name = {c.name: c.values for c in columns}
        arrays = []
        for item in self._schema:
            if item.name == self.time_label:
                arrays.append(arrow_texts(epochs))
            elif item.name == "tt_ns":
                arrays.append(pa.array(_nanoseconds(seconds)))
            elif item.name == "segment":
                arrays.append(pa.array(np.asarray(by_name["segment"]).astype(np.int32)))
            else:
                arrays.append(pa.array(np.asarray(by_name[item.name], dtype=np.float64)))
        self._writer.write_table(pa.Table.from_arrays(arrays, schema=self._schema))

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None

    def __enter__(self) -> ParquetWriter:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        if kind is None:
            self.close()
            return
        try:
            self.close()
        except Exception:  # the first error is the one to report (a full disk, ...)
            self._writer = None


def _nanoseconds(seconds: NDArray[np.float64]) -> NDArray[np.int64]:
    """TT seconds as int64 nanoseconds, rounded to the nearest: the whole seconds and
    the fraction apart, so that no product exceeds 2⁵³ before it is an integer."""
    whole = np.floor(seconds)
    return whole.astype(np.int64) * 1_000_000_000 + np.rint((seconds - whole) * 1e9).astype(
        np.int64
    )
