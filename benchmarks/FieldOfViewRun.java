// Orekit's field-of-view search for benchmarks/pointing_search_vs_orekit.py: a
// FieldOfViewDetector on a Keplerian propagator carrying a TorqueFree attitude, whose
// target is the Sun direction of the package (a table, so that both searches see the
// same Sun), counting the detector's g evaluations.  Compiled at run time by javac.
import java.util.ArrayList;
import java.util.List;
import org.hipparchus.geometry.euclidean.threed.Vector3D;
import org.hipparchus.ode.events.Action;
import org.orekit.frames.Frame;
import org.orekit.geometry.fov.FieldOfView;
import org.orekit.attitudes.AttitudeProvider;
import org.orekit.orbits.Orbit;
import org.orekit.propagation.SpacecraftState;
import org.orekit.propagation.analytical.KeplerianPropagator;
import org.orekit.propagation.events.EventDetectionSettings;
import org.orekit.propagation.events.EventDetector;
import org.orekit.propagation.events.FieldOfViewDetector;
import org.orekit.propagation.events.VisibilityTrigger;
import org.orekit.propagation.events.handlers.EventHandler;
import org.orekit.time.AbsoluteDate;
import org.orekit.utils.PVCoordinatesProvider;
import org.orekit.utils.TimeStampedPVCoordinates;

public class FieldOfViewRun {

    /** The Sun seen from the spacecraft: the spacecraft's position on its orbit plus a
     *  unit direction interpolated linearly (then normalized) in a table, times 1 au. */
    public static class SunFromTable implements PVCoordinatesProvider {
        private final Orbit orbit;
        private final double step;
        private final double[] x, y, z;

        public SunFromTable(Orbit orbit, double step, double[] x, double[] y, double[] z) {
            this.orbit = orbit;
            this.step = step;
            this.x = x;
            this.y = y;
            this.z = z;
        }

        @Override
        public Vector3D getPosition(AbsoluteDate date, Frame frame) {
            final double dt = date.durationFrom(orbit.getDate());
            final int k = Math.max(0, Math.min(x.length - 2, (int) Math.floor(dt / step)));
            final double s = dt / step - k;
            final Vector3D u = new Vector3D(
                    x[k] + s * (x[k + 1] - x[k]),
                    y[k] + s * (y[k + 1] - y[k]),
                    z[k] + s * (z[k + 1] - z[k])).normalize();
            return orbit.shiftedBy(dt).getPosition(frame).add(1.495978707e11, u);
        }

        @Override
        public TimeStampedPVCoordinates getPVCoordinates(AbsoluteDate date, Frame frame) {
            return new TimeStampedPVCoordinates(date, getPosition(date, frame), Vector3D.ZERO);
        }
    }

    /** FieldOfViewDetector that counts its g evaluations. */
    public static class Counting extends FieldOfViewDetector {
        public long calls;

        public Counting(EventDetectionSettings settings, EventHandler handler,
                        PVCoordinatesProvider target, FieldOfView fov) {
            super(settings, handler, target, 0.0, VisibilityTrigger.VISIBLE_AS_SOON_AS_PARTIALLY_IN_FOV, fov);
        }

        @Override
        public double g(SpacecraftState s) {
            calls++;
            return super.g(s);
        }

        @Override
        protected FieldOfViewDetector create(EventDetectionSettings settings, EventHandler handler) {
            return new Counting(settings, handler, getPVTarget(), getFOV());
        }
    }

    /** Records each event: its time from the start (s) and +1 entering the field of
     *  view (g decreasing: outside is positive), −1 leaving it. */
    public static class Recorder implements EventHandler {
        public final List<double[]> events = new ArrayList<>();
        private final AbsoluteDate start;

        public Recorder(AbsoluteDate start) {
            this.start = start;
        }

        @Override
        public Action eventOccurred(SpacecraftState s, EventDetector detector, boolean increasing) {
            events.add(new double[] {s.getDate().durationFrom(start), increasing ? -1.0 : 1.0});
            return Action.CONTINUE;
        }
    }

    /** A Keplerian propagator from ``orbit`` with ``attitude``, over [0, span]: returns
     *  the events flattened (time, sign, ...), then the g count last. */
    public static double[] run(Orbit orbit, AttitudeProvider attitude, PVCoordinatesProvider target,
                               FieldOfView fov, double maxCheck, double threshold, double span) {
        final KeplerianPropagator propagator = new KeplerianPropagator(orbit, attitude);
        final AbsoluteDate start = orbit.getDate();
        final Recorder recorder = new Recorder(start);
        final Counting detector = new Counting(
                new EventDetectionSettings(maxCheck, threshold, EventDetectionSettings.DEFAULT_MAX_ITER),
                recorder, target, fov);
        propagator.addEventDetector(detector);
        propagator.propagate(start, start.shiftedBy(span));
        final double[] out = new double[2 * recorder.events.size() + 1];
        for (int i = 0; i < recorder.events.size(); ++i) {
            out[2 * i] = recorder.events.get(i)[0];
            out[2 * i + 1] = recorder.events.get(i)[1];
        }
        out[out.length - 1] = detector.calls;
        return out;
    }
}
