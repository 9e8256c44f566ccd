"""Generate ``laws.json``: Orekit's attitude providers on our inputs (run where
orekit-jpype and a JDK are installed; the tests read the JSON only).

    PYTHONPATH=. /work/venv-bench/bin/python tests/data/orekit/generate_laws.py

Orekit is given the same inputs as our laws, so that the comparison checks the laws'
definitions, not the ephemerides or the Earth model:

- the orbit: a ``PVCoordinatesProvider`` written in Python that returns our Keplerian
  orbit's position, velocity and acceleration (``KeplerianOrbit.derivatives_tt``);
- the Sun and the Moon: ``ExtendedPositionProvider`` objects whose position is the
  spacecraft's plus our apparent vector from it (light time and aberration), with their
  derivatives, so that Orekit's ``body − spacecraft`` is our apparent direction;
- the Earth: ``FramesFactory.getITRF(IERS_2010, simpleEOP=true)`` through a
  ``DataContext`` built here from astropy-iers-data's ``finals2000A.all`` (the EOP our
  module reads) and a ``tai-utc.dat`` written from ERFA's leap seconds; the ellipsoid
  is WGS 84.
The ITRF → GCRF transform itself is saved too, to check our Earth rotation.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))  # tests/, for orekit_law_cases

import orekit_law_cases as cases  # noqa: E402

from attitude.laws.inputs import LawInputs  # noqa: E402


def start_orekit(directory: str):
    """Start the JVM with a data context holding our EOP and leap seconds only."""
    import erfa
    import orekit_jpype
    from astropy.utils import iers

    orekit_jpype.initVM()
    from java.io import File
    from org.orekit.data import DataContext, DirectoryCrawler, LazyLoadedDataContext

    shutil.copy(iers.IERS_A_FILE, os.path.join(directory, "finals2000A.all"))
    months = "JAN FEB MAR APR MAY JUN JUL AUG SEP OCT NOV DEC".split()
    lines = []
    for year, month, offset in erfa.leap_seconds.get():
        if year >= 1972:  # integral leap seconds only (the drifting UTC before is not used)
            jd = sum(erfa.cal2jd(int(year), int(month), 1))
            lines.append(
                f" {year} {months[month - 1]}  1 =JD {jd:.1f}  TAI-UTC= {offset:11.7f} S "
                "+ (MJD - 41317.) X 0.0      S"
            )
    Path(directory, "tai-utc.dat").write_text("\n".join(lines) + "\n")
    context = LazyLoadedDataContext()
    context.getDataProvidersManager().addProvider(DirectoryCrawler(File(directory)))
    DataContext.setDefault(context)


def main() -> None:
    import jpype

    directory = tempfile.mkdtemp(prefix="attitude-orekit-data-")
    start_orekit(directory)
    from org.hipparchus.geometry.euclidean.threed import Rotation as HRotation
    from org.hipparchus.geometry.euclidean.threed import RotationOrder, Vector3D
    from org.orekit.attitudes import (
        AlignedAndConstrained,
        BodyCenterPointing,
        CelestialBodyPointed,
        FrameAlignedProvider,
        GroundPointTarget,
        LofOffset,
        NadirPointing,
        PredefinedTarget,
        TargetPointing,
        YawCompensation,
        YawSteering,
    )
    from org.orekit.bodies import GeodeticPoint, OneAxisEllipsoid
    from org.orekit.frames import FramesFactory, LOFType
    from org.orekit.time import AbsoluteDate, TimeScalesFactory
    from org.orekit.utils import (
        Constants,
        ExtendedPositionProvider,
        IERSConventions,
        PVCoordinatesProvider,
        TimeStampedPVCoordinates,
    )

    gcrf = FramesFactory.getGCRF()
    itrf = FramesFactory.getITRF(IERSConventions.IERS_2010, True)
    earth = OneAxisEllipsoid(
        Constants.WGS84_EARTH_EQUATORIAL_RADIUS, Constants.WGS84_EARTH_FLATTENING, itrf
    )
    utc = TimeScalesFactory.getUTC()
    date_text = cases.EPOCH.replace("T", " ")
    day, clock = date_text.split()
    y, mo, d = (int(x) for x in day.split("-"))
    h, mi, s = clock.split(":")
    epoch_date = AbsoluteDate(y, mo, d, int(h), int(mi), float(s), utc)

    def vector(v) -> Vector3D:
        return Vector3D(float(v[0]), float(v[1]), float(v[2]))

    def in_frame(pv, frame):
        """GCRF coordinates to ``frame``'s (with the frame's rotation rate)."""
        if frame == gcrf:
            return pv
        return gcrf.getTransformTo(frame, pv.getDate()).transformPVCoordinates(pv)

    span = (float(cases.SECONDS.min()) - 60.0, float(cases.SECONDS.max()) + 60.0)

    def inputs_for(orbit_name: str) -> LawInputs:
        return LawInputs(cases.EPOCH, *span, orbit=cases.orbit(orbit_name))

    @jpype.JImplements(PVCoordinatesProvider)
    class OrbitProvider:
        def __init__(self, inputs: LawInputs) -> None:
            self.inputs = inputs

        def _jets(self, date):
            at = self.inputs.at([float(date.durationFrom(epoch_date))])
            return at.position.derivatives()[:3, 0]

        @jpype.JOverride
        def getPVCoordinates(self, date, frame):
            r, v, a = self._jets(date)
            return in_frame(TimeStampedPVCoordinates(date, vector(r), vector(v), vector(a)), frame)

        @jpype.JOverride
        def getPosition(self, date, frame):
            return self.getPVCoordinates(date, frame).getPosition()

    @jpype.JImplements(ExtendedPositionProvider)
    class BodyProvider:
        """The spacecraft's position plus our apparent vector to the body."""

        def __init__(self, inputs: LawInputs, body: str) -> None:
            self.inputs, self.body = inputs, body

        def _jets(self, date):
            at = self.inputs.at([float(date.durationFrom(epoch_date))])
            own = at.position.derivatives()[:3, 0]
            seen = at.apparent(self.body).derivatives()[:, 0]
            return own + seen

        @jpype.JOverride
        def getPVCoordinates(self, date, frame):
            p, v, a = self._jets(date)
            return in_frame(TimeStampedPVCoordinates(date, vector(p), vector(v), vector(a)), frame)

        @jpype.JOverride
        def getPosition(self, date, frame):
            if not isinstance(date, AbsoluteDate):
                raise NotImplementedError("field dates are not used by these cases")
            return self.getPVCoordinates(date, frame).getPosition()

    site = cases.site()
    geodetic = GeodeticPoint(site.latitude, site.longitude, site.height)
    inertial = HRotation(
        *cases.Rotation.from_rotvec(cases.INERTIAL_ROTVEC).as_quat(scalar_first=True), True
    )
    lof = LofOffset(gcrf, LOFType.LVLH_CCSDS, RotationOrder.XYZ, *cases.LOF_ANGLES)
    offset = lof.getOffset()
    offset_q = [offset.getQ0(), offset.getQ1(), offset.getQ2(), offset.getQ3()]
    ours = cases.lof_offset().as_quat(scalar_first=True)
    if np.dot(ours, offset_q) < 0:
        ours = -ours
    assert np.allclose(ours, offset_q, atol=1e-15), (ours, offset_q)

    def provider(case: str, sun, moon):
        nadir = NadirPointing(gcrf, earth)
        return {
            "inertial": lambda: FrameAlignedProvider(inertial, gcrf),
            "lvlh": lambda: LofOffset(gcrf, LOFType.LVLH_CCSDS),
            "lvlh_offset": lambda: lof,
            "rtn": lambda: LofOffset(gcrf, LOFType.QSW),
            "nadir": lambda: nadir,
            "nadir_heo": lambda: nadir,
            "body_centre": lambda: BodyCenterPointing(gcrf, earth),
            "zero_doppler": lambda: YawCompensation(gcrf, nadir),
            "yaw_steering": lambda: YawSteering(gcrf, nadir, sun, Vector3D.PLUS_I),
            "sun": lambda: CelestialBodyPointed(
                gcrf, sun, Vector3D.PLUS_K, Vector3D.PLUS_K, Vector3D.PLUS_I
            ),
            "moon": lambda: CelestialBodyPointed(
                gcrf, moon, Vector3D.PLUS_K, Vector3D.PLUS_K, Vector3D.PLUS_I
            ),
            "ground_site": lambda: TargetPointing(gcrf, geodetic, earth),
            "aligned_sun_momentum": lambda: AlignedAndConstrained(
                Vector3D.PLUS_I,
                PredefinedTarget.SUN,
                Vector3D.PLUS_K,
                PredefinedTarget.MOMENTUM,
                gcrf,
                sun,
                earth,
            ),
            "aligned_velocity_earth": lambda: AlignedAndConstrained(
                Vector3D.PLUS_J,
                PredefinedTarget.VELOCITY,
                Vector3D.MINUS_K,
                PredefinedTarget.EARTH,
                gcrf,
                sun,
                earth,
            ),
            "aligned_nadir_sun": lambda: AlignedAndConstrained(
                Vector3D.MINUS_K,
                PredefinedTarget.NADIR,
                Vector3D.PLUS_I,
                PredefinedTarget.SUN,
                gcrf,
                sun,
                earth,
            ),
            # The Moon through the "sun" slot: PredefinedTarget.SUN reads that provider.
            "aligned_site_moon": lambda: AlignedAndConstrained(
                Vector3D.PLUS_K,
                GroundPointTarget(vector(site.itrs_m)),
                Vector3D.PLUS_J,
                PredefinedTarget.SUN,
                gcrf,
                moon,
                earth,
            ),
        }[case]()

    out = {
        "epoch_utc": cases.EPOCH,
        "seconds": cases.SECONDS.tolist(),
        "lof_offset_quaternion_scalar_first": offset_q,
        "cases": {},
    }
    from importlib.metadata import version

    out["orekit"] = version("orekit-jpype")
    out["astropy_iers_data"] = version("astropy-iers-data")
    # The Earth's rotation: ITRF → GCRF at the epochs (Orekit's own IERS 2010 model).
    earth_rows = []
    for t in cases.SECONDS:
        date = epoch_date.shiftedBy(float(t))
        transform = itrf.getTransformTo(gcrf, date)
        rotation = transform.getRotation()
        rate = transform.getRotationRate()  # ITRF → GCRF: in the GCRF frame's sense
        ut1 = TimeScalesFactory.getUT1(IERSConventions.IERS_2010, True)
        earth_rows.append(
            {
                "q": [rotation.getQ0(), rotation.getQ1(), rotation.getQ2(), rotation.getQ3()],
                "rate": [rate.getX(), rate.getY(), rate.getZ()],
                "ut1_minus_utc": float(
                    ut1.offsetFromTAI(date).toDouble() - utc.offsetFromTAI(date).toDouble()
                ),
            }
        )
    out["itrf_to_gcrf"] = earth_rows
    for case, (orbit_name, _, _) in cases.CASES.items():
        inputs = inputs_for(orbit_name)
        orbit_provider = OrbitProvider(inputs)
        law = provider(case, BodyProvider(inputs, "sun"), BodyProvider(inputs, "moon"))
        rows = []
        for t in cases.SECONDS:
            attitude = law.getAttitude(orbit_provider, epoch_date.shiftedBy(float(t)), gcrf)
            r = attitude.getRotation()
            w = attitude.getSpin()
            a = attitude.getRotationAcceleration()
            rows.append(
                {
                    "q": [r.getQ0(), r.getQ1(), r.getQ2(), r.getQ3()],
                    "spin": [w.getX(), w.getY(), w.getZ()],
                    "acceleration": [a.getX(), a.getY(), a.getZ()],
                }
            )
        out["cases"][case] = rows
        print(case, "done", flush=True)
    # One line per case, numbers as Python writes them (repr: exact round trip).
    text = json.dumps(
        {k: v for k, v in out.items() if k not in ("cases", "itrf_to_gcrf")}, indent=1
    )
    body = ",\n".join(f" {json.dumps(k)}: {json.dumps(v)}" for k, v in out["cases"].items())
    earth = json.dumps(out["itrf_to_gcrf"])
    (HERE / "laws.json").write_text(
        text[:-2] + f',\n "itrf_to_gcrf": {earth},\n "cases": {{\n{body}\n }}\n}}\n'
    )
    shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    main()
