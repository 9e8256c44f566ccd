// Evaluates an Orekit TorqueFree attitude provider at many dates in one JVM call.
// Compiled at run time by benchmarks/peer_orekit.py (javac, into a temporary
// directory); without javac the benchmark falls back to a per-sample JPype loop.
import org.hipparchus.geometry.euclidean.threed.Rotation;
import org.hipparchus.geometry.euclidean.threed.Vector3D;
import org.orekit.attitudes.Attitude;
import org.orekit.attitudes.TorqueFree;
import org.orekit.frames.Frame;
import org.orekit.time.AbsoluteDate;

public class TorqueFreeBulk {
    /** Per date: q0..q3 of Attitude.getRotation() (frame to body) and the spin (body axes). */
    public static double[] evaluate(TorqueFree tf, AbsoluteDate t0, Frame frame, double[] dt) {
        final double[] out = new double[7 * dt.length];
        for (int i = 0; i < dt.length; ++i) {
            final Attitude a = tf.getAttitude(null, t0.shiftedBy(dt[i]), frame);
            final Rotation r = a.getRotation();
            final Vector3D w = a.getSpin();
            out[7 * i] = r.getQ0();
            out[7 * i + 1] = r.getQ1();
            out[7 * i + 2] = r.getQ2();
            out[7 * i + 3] = r.getQ3();
            out[7 * i + 4] = w.getX();
            out[7 * i + 5] = w.getY();
            out[7 * i + 6] = w.getZ();
        }
        return out;
    }
}
