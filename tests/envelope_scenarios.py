"""The example's scenario with another ``[envelope]`` table, for the envelope's tests."""

from pathlib import Path

EXAMPLE = Path(__file__).parents[1] / "scenarios" / "eo_envelope.toml"


def with_envelope(tmp_path: Path, table: str, name: str = "eo.toml") -> Path:
    """The example with ``table`` (TOML text, its header included) in place of its
    ``[envelope]`` table, written to ``tmp_path / name``."""
    text = EXAMPLE.read_text()
    head = text[: text.index("[envelope]")]
    path = tmp_path / name
    path.write_text(head + table + "\n")
    return path
