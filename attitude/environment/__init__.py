"""Where the spacecraft is and what surrounds it, independent of its attitude: time scales
and epochs, the Sun and Moon ephemeris, the Earth, orbit-relative frames, and orbits
(TLE, Keplerian, CCSDS OEM).

Modules:

- ``ccsds``: What reading a CCSDS OEM or AEM file takes, shared by
  :mod:`attitude.environment.oem` and :mod:`attitude.files.aem_reader`: the parser, time
  systems, epochs, and interpolation.
- ``earth``: The Earth seen from the spacecraft: its size, its angular radius, nadir and
  the limb.
- ``earth_rotation``: The Earth's rotation: ITRS → GCRS with its time derivatives,
  offline; geodetic sites.
- ``ephemeris``: Sun and Moon vectors from JPL DE421 through skyfield, offline: where
  they appear.
- ``epoch_texts``: ISO 8601 texts of many epochs, fast: integer nanoseconds and numpy's
  calendar.
- ``frames``: Orbit-relative frames (LVLH, RTN), the EME2000 frame bias, and Euler
  angles.
- ``keplerian``: An orbit from Keplerian elements at an epoch: two-body motion, or with
  J2's secular drift.
- ``oem``: An orbit read from a CCSDS Orbit Ephemeris Message (OEM, CCSDS 502.0-B-3,
  KVN).
- ``orbit``: Where the spacecraft is: the orbit sources, and SGP4 from a TLE evaluated
  exactly.
- ``timescales``: Epochs: astropy Time without a network, and exact arithmetic between
  epochs.
"""
