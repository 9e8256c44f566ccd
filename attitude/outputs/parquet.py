"""``timeseries.parquet``: the time series in Apache Parquet, a row group per chunk.

CSV stops being practical around a gigabyte (a 30-day run at 1 s writes 1.7 GB of
it); Parquet is the columnar format the PyData world reads (pandas, polars, DuckDB,
Spark, Arrow itself), compressed (zstd) and typed.  The file holds the same columns as
``timeseries.csv``, in the same units, plus an exact time column:

- ``time_<scale>``: the ISO 8601 epoch text in the scenario's time scale, to 1 ns,
  exactly as in the CSV.  In UTC a sample inside a leap second reads
  ``…T23:59:60.…``, as UTC writes it.  Readers that parse such texts into POSIX
  timestamps misread them: pandas' ``to_datetime`` and polars read
  ``2016-12-31T23:59:60.5`` as ``2017-01-01T00:00:00.5`` (a second repeated, a span
  one second short), pyarrow and DuckDB refuse it.
- ``timestamp_tt``: the same instant as an Arrow ``timestamp`` (no time zone) **in
  TT**: nanoseconds since 1970-01-01T00:00:00 TT on TT's own uniform calendar, which
  has no leap seconds, so that every reader (pandas, polars, DuckDB, Spark, Arrow)
  takes it for what it is: increasing, uniform, and differences that are elapsed
  seconds.  It is the column to plot against and to join on; its calendar texts are
  TT's (32.184 s + TAI − UTC ahead of UTC: 69.184 s since 2017).  Nanoseconds from
  1970 reach the years 1677–2262; a span outside them is written in microseconds
  (``timestamp[us]``, rounded to the nearest), and the field's metadata says so.
- ``tt_ns``: int64, TT nanoseconds since the scenario epoch (``epoch_tt`` in the
  metadata), the uniform count the solver uses: exact and monotonic.  Convert with
  astropy, ``Time(epoch_tt, scale="tt") + TimeDelta(tt_ns * 1e-9, format="sec")``, for
  any other time scale.  int64 nanoseconds count 292 years; a longer span is refused.
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

__all__ = [
    "MAX_SPAN_S",
    "TIMESTAMP_NS_RANGE_S",
    "ParquetWriter",
    "check_span",
    "timestamp_unit",
    "tt_nanoseconds_since_1970",
    "unit_of",
]

# int64 nanoseconds: ±9.2e18 ns, 292 years.
MAX_SPAN_S = float(np.iinfo(np.int64).max) / 1e9
COMPRESSION = "zstd"
# What int64 nanoseconds from 1970-01-01 reach (1677-09-21 to 2262-04-11): the range
# of a timestamp[ns]; beyond it the timestamp column is written in microseconds.
TIMESTAMP_NS_RANGE_S = float(np.iinfo(np.int64).max) / 1e9

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
    values that are not text are written as JSON); ``epoch_tt``: the scenario epoch in
    TT, an ISO 8601 text to 1 ns (``2017-01-01T00:00:32.184000000``), for the
    ``timestamp_tt`` column (none without it).  The schema is fixed by the first
    chunk, and so is the timestamp's unit: nanoseconds, or microseconds for a span
    beyond the years 1677–2262 (:data:`TIMESTAMP_NS_RANGE_S`; ``span_s``: the first
    and last TT seconds since the epoch that will be written).  A context manager: the
    file is finished (its footer written) on exit; after an error, as far as it can be,
    for the caller to remove.
    """

    def __init__(
        self,
        path: Path,
        time_label: str,
        metadata: dict[str, Any],
        time_description: str,
        epoch_tt: str | None = None,
        span_s: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        self.path = Path(path)
        self.time_label = time_label
        # TT nanoseconds of the epoch since 1970-01-01T00:00:00 TT (None: no timestamp
        # column), and the unit of the timestamp column (chosen with the first chunk).
        self._epoch_ns = None if epoch_tt is None else tt_nanoseconds_since_1970(epoch_tt)
        self._span_s = span_s
        self._unit = "ns"
        self._metadata = {
            f"attitude.{key}": value if isinstance(value, str) else json.dumps(value)
            for key, value in metadata.items()
        }
        self._time_description = time_description
        # pyarrow is untyped: a ParquetWriter and a Schema, once the first chunk is seen.
        self._writer: Any = None
        self._schema: Any = None

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
        if self._epoch_ns is not None:
            fields.append(
                field(
                    "timestamp_tt",
                    pa.timestamp(self._unit),
                    self._unit,
                    f"the epoch in TT as a timestamp ({self._unit} since "
                    "1970-01-01T00:00:00 TT, TT's calendar: no leap seconds), uniform; "
                    "the column to order, plot and difference by",
                )
            )
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
            if self._epoch_ns is not None:
                self._unit = timestamp_unit(self._epoch_ns, self._span_s)
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
            elif item.name == "timestamp_tt" and self._epoch_ns is not None:
                arrays.append(pa.array(_timestamps(self._epoch_ns, seconds, self._unit), item.type))
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


def tt_nanoseconds_since_1970(epoch_tt: str) -> int:
    """TT nanoseconds from 1970-01-01T00:00:00 TT to ``epoch_tt`` (an ISO 8601 text in
    TT, to 1 ns at most), exactly, as a Python int.

    TT's calendar is uniform (86 400 SI seconds a day, no leap seconds), so numpy's
    datetime64 arithmetic, which assumes just that, is exact on TT texts: the seconds
    and the fraction are read apart so that no year is out of range.
    """
    text = epoch_tt.strip().removesuffix("TT").strip()
    whole, _, fraction = text.partition(".")
    seconds = int(np.datetime64(whole, "s").astype(np.int64))
    digits = (fraction + "000000000")[:9]
    if not digits.isdigit() or len(fraction) > 9:
        raise ValueError(f"epoch_tt: expected an ISO 8601 text to 1 ns, got {epoch_tt!r}")
    return seconds * 1_000_000_000 + int(digits)


def timestamp_unit(epoch_ns: int, span_s: tuple[float, float]) -> str:
    """ "ns" when every epoch of the span (TT s since the epoch, ``span_s``) is within
    int64 nanoseconds of 1970, else "us"."""
    reach = TIMESTAMP_NS_RANGE_S * 1e9 - 1e9  # a second of margin for the rounding
    ends = [epoch_ns + float(s) * 1e9 for s in span_s]
    return "ns" if all(abs(end) < reach for end in ends) else "us"


def _timestamps(epoch_ns: int, seconds: NDArray[np.float64], unit: str) -> NDArray[np.int64]:
    """The timestamps (``unit`` since 1970-01-01T00:00:00 TT) of TT ``seconds`` since the
    epoch: the epoch's exact nanoseconds plus :func:`_nanoseconds`, in integers."""
    offsets = _nanoseconds(seconds)
    if unit == "ns":
        return np.int64(epoch_ns) + offsets
    # Microseconds: the epoch and the offsets each rounded, then added (the epoch alone
    # can exceed int64 nanoseconds).
    epoch_us = (epoch_ns + 500) // 1000
    return np.int64(epoch_us) + (offsets + 500) // 1000
