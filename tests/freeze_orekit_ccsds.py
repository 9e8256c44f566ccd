"""Regenerate tests/data/orekit/: the AEM and OEM interchange with Orekit, frozen.

    PYTHONPATH=. /work/venv-bench/bin/python tests/freeze_orekit_ccsds.py

It runs only where orekit-jpype and a Java runtime are installed (``pip install
'.[bench]'``); the tests read what it writes and need neither.  Three things are frozen:

1. **Our AEM files read by Orekit** (``aem_read_by_orekit/<example>.csv``): every
   example of ``scenarios/`` is run with ``--formats aem``; Orekit's CCSDS parser
   (``org.orekit.files.ccsds.ndm.ParserBuilder().buildAemParser()``) reads the file and
   each segment's own attitude provider (``AemSegment.getAttitudeProvider()``: Orekit's
   interpolation of the records, over the samples the file declares) gives the attitude
   at mid-steps of the records (the first and last ones of each segment, those within a
   minute of an event or a burn's start or end, and an even spread of the others).  The
   header states the file read (its SHA-256, its records per segment, the tolerance it
   declares) so that the test can tell stale data from a failure.
2. **An AEM written by Orekit** (``orekit_written.aem``): Orekit's ``TorqueFree``
   attitude of a tumbling body, in EME2000, every second across the 2016-12-31 leap
   second, in UTC, written by ``StreamingAemWriter``; ``orekit_written_aem_truth.csv``
   holds, at mid-steps and records, Orekit's attitude from the provider itself and from
   its own reading of the file, both in GCRF.
3. **An OEM written by Orekit** (``orekit_written.oem``): a Keplerian orbit in EME2000
   across the same leap second, every 60 s, LAGRANGE degree 7, in UTC, written by
   ``StreamingOemWriter``; ``orekit_written_oem_truth.csv`` holds the orbit's own states
   and Orekit's reading of the file, in GCRF.

Orekit's data: none is installed (no orekit-data).  Its UTC comes from ERFA's
leap-second table (pyerfa, the table astropy uses), from 1972 on; the Earth is the
origin of GCRF; the solar system barycentre, whose inertial frame is what Orekit calls
ICRF (our AEM's REF_FRAME_A), is placed from the DE421 ephemeris of skyfield-data.  No
Earth orientation data is needed: every frame here is GCRF, EME2000 or ICRF.
"""

from __future__ import annotations

import hashlib
import json
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).parents[1]
DATA = Path(__file__).parent / "data" / "orekit"
# Mid-steps kept per segment beside the first and last ones and those near events.
SPREAD = 30
# Mid-steps this close (s) to an event or a burn's start or end are all kept.
NEAR_S = 20.0


# ------------------------------------------------------------------ Orekit and its data


def start() -> None:
    import orekit_jpype

    orekit_jpype.initVM()


def data_context():
    """A LazyLoadedDataContext fed from what this project has (module notes)."""
    import erfa
    from java.lang import UnsupportedOperationException
    from java.util import ArrayList
    from jpype import JImplements, JOverride
    from org.hipparchus.geometry.euclidean.threed import Vector3D
    from org.orekit.bodies import CelestialBodyFactory
    from org.orekit.data import LazyLoadedDataContext
    from org.orekit.frames import Frame, Transform
    from org.orekit.time import DateComponents, OffsetModel
    from org.orekit.utils import Constants, PVCoordinates, TimeStampedPVCoordinates

    context = LazyLoadedDataContext()

    @JImplements("org.orekit.time.UTCTAIOffsetsLoader")
    class ErfaLeapSeconds:
        @JOverride
        def loadOffsets(self):
            offsets = ArrayList()
            for year, month, tai_utc in erfa.leap_seconds.get():
                if year >= 1972:  # whole seconds since; the drift before is not needed
                    offsets.add(OffsetModel(DateComponents(int(year), int(month), 1), int(tai_utc)))
            return offsets

    context.getTimeScales().addUTCTAIOffsetsLoader(ErfaLeapSeconds())
    gcrf = context.getFrames().getGCRF()
    tt = context.getTimeScales().getTT()

    from skyfield.api import load_file
    from skyfield_data import get_skyfield_data_path

    planets = load_file(str(Path(get_skyfield_data_path()) / "de421.bsp"))
    earth = planets["earth"]
    from skyfield.api import load

    timescale = load.timescale(builtin=True)
    from org.orekit.time import AbsoluteDate

    tt_j2000 = AbsoluteDate(2000, 1, 1, 12, 0, 0.0, tt)

    @JImplements("org.orekit.frames.TransformProvider")
    class BarycentreFromDe421:
        """GCRF → ICRF (origin at the solar system barycentre, the same axes): the
        translation is the Earth's barycentric position and velocity (DE421)."""

        @JOverride
        def getTransform(self, date):
            if not isinstance(date, AbsoluteDate):
                raise UnsupportedOperationException("field dates are not needed here")
            seconds = float(date.durationFrom(tt_j2000))
            at = timescale.tt_jd(2451545.0, seconds / 86400.0)
            state = earth.at(at)
            r = state.position.m
            v = state.velocity.m_per_s
            pv = PVCoordinates(
                Vector3D(float(r[0]), float(r[1]), float(r[2])),
                Vector3D(float(v[0]), float(v[1]), float(v[2])),
            )
            return Transform(date, pv)

    icrf = Frame(gcrf, BarycentreFromDe421(), "ICRF (DE421)", True)

    def body(name, inertial, gm):
        @JImplements("org.orekit.bodies.CelestialBody")
        class Body:
            @JOverride
            def getInertiallyOrientedFrame(self):
                return inertial

            @JOverride
            def getBodyOrientedFrame(self):
                raise UnsupportedOperationException(f"{name}: no body-oriented frame here")

            @JOverride
            def getName(self):
                return name

            @JOverride
            def getGM(self):
                return gm

            @JOverride
            def getPVCoordinates(self, date, frame):
                origin = inertial.getTransformTo(frame, date)
                return TimeStampedPVCoordinates(
                    date, origin.transformPVCoordinates(PVCoordinates.ZERO)
                )

            @JOverride
            def getPosition(self, date, frame):
                raise UnsupportedOperationException("field dates are not needed here")

        return Body()

    bodies = {
        CelestialBodyFactory.EARTH: body("Earth", gcrf, Constants.IERS2010_EARTH_MU),
        CelestialBodyFactory.SOLAR_SYSTEM_BARYCENTER: body(
            "solar system barycenter", icrf, 1.32712440041279419e20 + 0.0
        ),
    }

    @JImplements("org.orekit.bodies.CelestialBodyLoader")
    class Loader:
        @JOverride
        def loadCelestialBody(self, name):
            return bodies[str(name)]

    for name in bodies:
        context.getCelestialBodies().addCelestialBodyLoader(name, Loader())
    return context


def rotation_to_ours(rotation) -> list[float]:
    """Hipparchus' rotation frame → body (q0..q3) as our scalar-first quaternion of body
    → frame: the same four numbers (benchmarks/peer_orekit.py has the derivation)."""
    return [rotation.getQ0(), rotation.getQ1(), rotation.getQ2(), rotation.getQ3()]


def orekit_date(context, scale: str, text: str):
    from org.orekit.time import AbsoluteDate

    scales = context.getTimeScales()
    return AbsoluteDate(text, {"UTC": scales.getUTC(), "TT": scales.getTT()}[scale])


# ------------------------------------------------------------ 1. our AEM files, read by Orekit


def _mid_steps(records_s: np.ndarray, boundaries_s: list[float]) -> np.ndarray:
    """The mid-steps kept for one segment (module notes)."""
    mids = 0.5 * (records_s[1:] + records_s[:-1])
    keep = np.zeros(mids.size, dtype=bool)
    keep[:3] = keep[-3:] = True
    for boundary in boundaries_s:
        keep |= np.abs(mids - boundary) <= NEAR_S
    keep[np.unique(np.linspace(0, mids.size - 1, min(SPREAD, mids.size)).astype(int))] = True
    return mids[keep]


def _declared_tolerance(text: str) -> float:
    found = re.search(
        r"stays within ([0-9.eE+-]+) rad of the exact attitude", text.replace("\nCOMMENT ", " ")
    )
    assert found, "the AEM states no tolerance"
    return float(found.group(1))


def our_aem_read_by_orekit(context, example: Path, folder: Path) -> str:
    """The CSV text of Orekit's reading of ``example``'s AEM (module notes, 1)."""
    from aem_read_back import read_back
    from java.io import File
    from org.orekit.data import DataSource
    from org.orekit.files.ccsds.ndm import ParserBuilder

    from attitude.environment.timescales import iso_texts, offline_time, tt_seconds
    from attitude.files.scenario_reader import load_scenario
    from attitude.outputs.formats import OutputChoice
    from attitude.report.plan import plan_run
    from attitude.report.run import write_report

    loaded = load_scenario(example)
    scenario = loaded.scenario
    outputs = OutputChoice(("aem",), loaded.outputs.aem_tolerance_rad)
    # The validity horizon here, not in a process forked beside the run: a fork of a
    # process that holds a JVM can hang.
    plan = plan_run(scenario, loaded.pointing, outputs, horizon=True)
    write_report(scenario, folder, plan=plan)
    path = folder / "attitude.aem"
    text = path.read_text()
    segments, _ = read_back(path)
    boundaries = [t for t, _ in scenario.events]
    boundaries += [b for burn in scenario.burns for b in (burn.start_s, burn.stop_s)]
    records = [tt_seconds(segment.times, scenario.epoch) for segment in segments]
    mids = [_mid_steps(x, boundaries) for x in records]

    message = ParserBuilder(context).buildAemParser().parseMessage(DataSource(File(str(path))))
    (satellite,) = list(message.getSatellites().values())
    parsed = list(satellite.getSegments())
    assert len(parsed) == len(segments)
    gcrf = context.getFrames().getGCRF()
    with offline_time():
        epoch_tt = str(iso_texts(scenario.times(0.0).tt))
    epoch = orekit_date(context, "TT", epoch_tt)
    rows = []
    for index, (segment, times) in enumerate(zip(parsed, mids, strict=True)):
        provider = segment.getAttitudeProvider()
        for t in times:
            attitude = provider.getAttitude(None, epoch.shiftedBy(float(t)), gcrf)
            q = rotation_to_ours(attitude.getRotation())
            rows.append(f"{index},{float(t)!r}," + ",".join(repr(float(c)) for c in q))
    header = [
        f"# {example.name}: attitude.aem written by attitude, read by Orekit {_orekit_version()}",
        "# (ParserBuilder.buildAemParser, AemSegment.getAttitudeProvider, in GCRF) at mid-steps",
        f"# aem_sha256: {hashlib.sha256(path.read_bytes()).hexdigest()}",
        f"# records_per_segment: {json.dumps([int(x.size) for x in records])}",
        f"# first_and_last_record_s: {json.dumps([[float(x[0]), float(x[-1])] for x in records])}",
        f"# declared_tolerance_rad: {_declared_tolerance(text)!r}",
        f"# epoch_tt: {epoch_tt}",
        "# t_s: TT seconds since the scenario epoch; q: body -> GCRF, scalar first",
        "segment,t_s,q_w,q_x,q_y,q_z",
    ]
    return "\n".join(header + rows) + "\n"


def _orekit_version() -> str:
    """Orekit's version, from the name of the jar orekit-jpype ships."""
    import orekit_jpype

    jars = Path(orekit_jpype.__file__).parent / "jars"
    (jar,) = jars.glob("orekit-*.jar")
    return jar.stem.removeprefix("orekit-")


# ------------------------------------------------------------ 2. an AEM written by Orekit

# Across the 2016-12-31 leap second, in UTC: the file starts a minute before it.
START_UTC = "2016-12-31T23:59:00.000"
AEM_STEP_S, AEM_RECORDS = 1.0, 121
OEM_STEP_S, OEM_RECORDS = 60.0, 121
# The tumbling body of Orekit's TorqueFree: principal moments (kg m²), rate (rad/s).
INERTIA = (100.0, 200.0, 300.0)
SPIN = (0.05, 0.02, -0.03)


def _parse(context, kind: str, text: str):
    """``text`` (a CCSDS message) parsed by Orekit's parser of ``kind`` ("aem", "oem")."""
    from java.io import File
    from org.orekit.data import DataSource
    from org.orekit.files.ccsds.ndm import ParserBuilder

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"message.{kind}"
        path.write_text(text)
        builder = ParserBuilder(context)
        parser = builder.buildAemParser() if kind == "aem" else builder.buildOemParser()
        return parser.parseMessage(DataSource(File(str(path))))


def _header(context, kind: str):
    from org.orekit.files.ccsds.ndm.adm import AdmHeader
    from org.orekit.files.ccsds.ndm.odm import OdmHeader

    header = AdmHeader() if kind == "adm" else OdmHeader()
    header.setFormatVersion(2.0 if kind == "adm" else 3.0)
    header.setOriginator("OREKIT")
    header.setCreationDate(orekit_date(context, "UTC", "2026-01-01T00:00:00.000"))
    return header


def orekit_written_aem(context) -> tuple[str, str]:
    """(the AEM text, the truth CSV text): module notes, 2."""
    from java.lang import StringBuilder
    from org.hipparchus.geometry.euclidean.threed import Rotation as HRotation
    from org.hipparchus.geometry.euclidean.threed import Vector3D
    from org.orekit.attitudes import Attitude, Inertia, InertiaAxis, TorqueFree
    from org.orekit.files.ccsds.definitions import (
        BodyFacade,
        CenterName,
        FrameFacade,
        SpacecraftBodyFrame,
        TimeSystem,
    )
    from org.orekit.files.ccsds.ndm import WriterBuilder
    from org.orekit.files.ccsds.ndm.adm import AttitudeType
    from org.orekit.files.ccsds.ndm.adm.aem import AemMetadata, AemWriter, StreamingAemWriter
    from org.orekit.files.ccsds.utils.generation import KvnGenerator
    from org.orekit.orbits import CircularOrbit, PositionAngleType
    from org.orekit.propagation import SpacecraftState
    from org.orekit.utils import Constants

    frames = context.getFrames()
    eme2000, gcrf = frames.getEME2000(), frames.getGCRF()
    start = orekit_date(context, "UTC", START_UTC)
    axes = Inertia(
        InertiaAxis(INERTIA[0], Vector3D.PLUS_I),
        InertiaAxis(INERTIA[1], Vector3D.PLUS_J),
        InertiaAxis(INERTIA[2], Vector3D.PLUS_K),
    )
    first = Attitude(
        start,
        eme2000,
        HRotation(0.9, 0.1, -0.3, 0.2, True),  # normalized by Hipparchus
        Vector3D(*SPIN),
        Vector3D.ZERO,
    )
    provider = TorqueFree(first, axes)
    orbit = CircularOrbit(
        6878137.0,
        0.0,
        0.0,
        1.7,
        0.3,
        0.0,
        PositionAngleType.MEAN,
        eme2000,
        start,
        Constants.IERS2010_EARTH_MU,
    )
    stop = start.shiftedBy(AEM_STEP_S * (AEM_RECORDS - 1))

    metadata = AemMetadata(7)
    metadata.setObjectName("TUMBLER")
    metadata.setObjectID("2016-999A")
    metadata.setCenter(BodyFacade.create(CenterName.EARTH, context))
    metadata.getEndpoints().setFrameA(FrameFacade.map(eme2000))
    body = SpacecraftBodyFrame.parse("SC_BODY_1")
    metadata.getEndpoints().setFrameB(FrameFacade(None, None, None, body, "SC_BODY_1"))
    metadata.getEndpoints().setA2b(True)
    metadata.setTimeSystem(TimeSystem.UTC)
    metadata.setAttitudeType(AttitudeType.QUATERNION)
    metadata.setIsFirst(False)
    metadata.setStartTime(start)
    metadata.setStopTime(stop)
    metadata.setInterpolationMethod("LAGRANGE")
    metadata.setInterpolationDegree(7)

    writer = WriterBuilder(context).buildAemWriter()
    buffer = StringBuilder()
    generator = KvnGenerator(buffer, AemWriter.KVN_PADDING_WIDTH, "orekit_written.aem", 86400.0, 0)
    streaming = StreamingAemWriter(generator, writer, _header(context, "adm"), metadata)
    segment = streaming.newSegment()

    def state(date):
        return SpacecraftState(
            orbit.shiftedBy(date.durationFrom(start)), provider.getAttitude(orbit, date, eme2000)
        )

    segment.init(state(start), stop, AEM_STEP_S)
    for k in range(AEM_RECORDS):
        segment.handleStep(state(start.shiftedBy(AEM_STEP_S * k)))
    segment.finish(state(stop))
    streaming.close()
    aem_text = str(buffer.toString())

    # Orekit's reading of its own file, and the provider itself, in GCRF.
    message = _parse(context, "aem", aem_text)
    (satellite,) = list(message.getSatellites().values())
    (parsed,) = list(satellite.getSegments())
    read = parsed.getAttitudeProvider()
    offsets = sorted(
        {AEM_STEP_S * (k + f) for k in range(AEM_RECORDS - 1) for f in (0.0, 0.5)}
        | {AEM_STEP_S * (AEM_RECORDS - 1)}
    )
    rows = []
    for t in offsets:
        date = start.shiftedBy(t)
        truth = provider.getAttitude(orbit, date, gcrf).getRotation()
        own = read.getAttitude(orbit, date, gcrf).getRotation()
        rows.append(
            f"{t!r},"
            + ",".join(repr(float(c)) for c in rotation_to_ours(truth) + rotation_to_ours(own))
        )
    header = [
        f"# orekit_written.aem: Orekit {_orekit_version()} TorqueFree, inertia "
        f"{list(INERTIA)} kg m2,",
        f"# spin {list(SPIN)} rad/s (body), written in EME2000 and UTC every {AEM_STEP_S} s",
        f"# start_utc: {START_UTC}",
        "# t_s: TT seconds after start_utc; truth: the provider's attitude; orekit_read:",
        "# Orekit's own reading of the file; both body -> GCRF, scalar first",
        "t_s,truth_w,truth_x,truth_y,truth_z,orekit_read_w,orekit_read_x,orekit_read_y,orekit_read_z",
    ]
    return aem_text, "\n".join(header + rows) + "\n"


# ------------------------------------------------------------ 3. an OEM written by Orekit


def orekit_written_oem(context) -> tuple[str, str]:
    """(the OEM text, the truth CSV text): module notes, 3."""
    from java.lang import StringBuilder
    from org.orekit.files.ccsds.definitions import BodyFacade, CenterName, FrameFacade, TimeSystem
    from org.orekit.files.ccsds.ndm import WriterBuilder
    from org.orekit.files.ccsds.ndm.odm.oem import (
        InterpolationMethod,
        OemMetadata,
        OemWriter,
        StreamingOemWriter,
    )
    from org.orekit.files.ccsds.utils.generation import KvnGenerator
    from org.orekit.orbits import KeplerianOrbit, PositionAngleType
    from org.orekit.propagation import SpacecraftState
    from org.orekit.utils import Constants

    frames = context.getFrames()
    eme2000, gcrf = frames.getEME2000(), frames.getGCRF()
    start = orekit_date(context, "UTC", START_UTC)
    orbit = KeplerianOrbit(
        7200e3,
        0.05,
        1.1,
        0.4,
        2.0,
        0.3,
        PositionAngleType.MEAN,
        eme2000,
        start,
        Constants.IERS2010_EARTH_MU,
    )
    stop = start.shiftedBy(OEM_STEP_S * (OEM_RECORDS - 1))
    metadata = OemMetadata(7)
    metadata.setObjectName("ORBITER")
    metadata.setObjectID("2016-998A")
    metadata.setCenter(BodyFacade.create(CenterName.EARTH, context))
    metadata.setReferenceFrame(FrameFacade.map(eme2000))
    metadata.setTimeSystem(TimeSystem.UTC)
    metadata.setStartTime(start)
    metadata.setStopTime(stop)
    metadata.setInterpolationMethod(InterpolationMethod.LAGRANGE)
    metadata.setInterpolationDegree(7)
    writer = WriterBuilder(context).buildOemWriter()
    buffer = StringBuilder()
    generator = KvnGenerator(buffer, OemWriter.KVN_PADDING_WIDTH, "orekit_written.oem", 86400.0, 0)
    streaming = StreamingOemWriter(generator, writer, _header(context, "odm"), metadata)
    segment = streaming.newSegment()

    def state(date):
        return SpacecraftState(orbit.shiftedBy(date.durationFrom(start)))

    segment.init(state(start), stop, OEM_STEP_S)
    for k in range(OEM_RECORDS):
        segment.handleStep(state(start.shiftedBy(OEM_STEP_S * k)))
    segment.finish(state(stop))
    streaming.close()
    oem_text = str(buffer.toString())

    message = _parse(context, "oem", oem_text)
    (satellite,) = list(message.getSatellites().values())
    (parsed,) = list(satellite.getSegments())
    read = parsed.getPropagator()
    offsets = sorted(
        {OEM_STEP_S * (k + f) for k in range(OEM_RECORDS - 1) for f in (0.0, 0.5)}
        | {OEM_STEP_S * (OEM_RECORDS - 1)}
    )
    rows = []
    for t in offsets:
        date = start.shiftedBy(t)
        truth = orbit.shiftedBy(t).getPVCoordinates(gcrf)
        own = read.propagate(date).getPVCoordinates(gcrf)
        values = []
        for pv in (truth, own):
            for vector in (pv.getPosition(), pv.getVelocity()):
                values += [vector.getX(), vector.getY(), vector.getZ()]
        rows.append(f"{t!r}," + ",".join(repr(float(v)) for v in values))
    header = [
        f"# orekit_written.oem: Orekit {_orekit_version()} KeplerianOrbit (two-body), written in",
        f"# EME2000 and UTC every {OEM_STEP_S} s, LAGRANGE degree 7",
        f"# start_utc: {START_UTC}",
        "# t_s: TT seconds after start_utc; truth: the orbit's own state; orekit_read: Orekit's",
        "# own reading of the file (OemSegment.getPropagator); both GCRF, m and m/s",
        "t_s,"
        + ",".join(
            f"{who}_{what}_{axis}"
            for who in ("truth", "orekit_read")
            for what in ("r", "v")
            for axis in "xyz"
        ),
    ]
    return oem_text, "\n".join(header + rows) + "\n"


# ------------------------------------------------------------------------------ main


def main() -> None:
    import warnings

    sys.path.insert(0, str(Path(__file__).parent))  # aem_read_back
    warnings.simplefilter("ignore")  # skyfield-data's stale finals2000A: not used here
    start()
    context = data_context()
    (DATA / "aem_read_by_orekit").mkdir(parents=True, exist_ok=True)
    for example in sorted((ROOT / "scenarios").glob("*.toml")):
        with tempfile.TemporaryDirectory() as folder:
            text = our_aem_read_by_orekit(context, example, Path(folder) / "out")
        (DATA / "aem_read_by_orekit" / f"{example.stem}.csv").write_text(text)
        print(f"{example.name}: {text.count(chr(10)) - 9} epochs read by Orekit", flush=True)
    aem, truth = orekit_written_aem(context)
    (DATA / "orekit_written.aem").write_text(aem)
    (DATA / "orekit_written_aem_truth.csv").write_text(truth)
    oem, truth = orekit_written_oem(context)
    (DATA / "orekit_written.oem").write_text(oem)
    (DATA / "orekit_written_oem_truth.csv").write_text(truth)
    print(f"written into {DATA}")


if __name__ == "__main__":
    main()
