// Writes the triangles of a jMonkeyEngine .j3o model as a Wavefront OBJ, in world
// space and the model's own units and axes (jME: Y up), one OBJ object per
// geometry. Used by catalog.py for the Sponza of jme3-testdata; compiled there
// against jme3-core (Maven Central).
//
//     java -cp jme3-core.jar:CLASSES J3oToObj model.j3o out.obj
//
// Only geometry is read: no asset locator is registered, so the model's
// material definition is not loaded (jME logs that once) and the material stays
// empty; the Sponza of jme3-testdata has no textures in the jar either.

import com.jme3.asset.DesktopAssetManager;
import com.jme3.export.binary.BinaryImporter;
import com.jme3.math.Vector3f;
import com.jme3.scene.Geometry;
import com.jme3.scene.Mesh;
import com.jme3.scene.Spatial;
import com.jme3.scene.VertexBuffer;
import java.io.BufferedWriter;
import java.io.File;
import java.io.FileWriter;
import java.io.PrintWriter;
import java.nio.FloatBuffer;
import java.util.ArrayList;
import java.util.List;
import java.util.logging.Level;
import java.util.logging.Logger;

public class J3oToObj {
    public static void main(String[] args) throws Exception {
        Logger.getLogger("").setLevel(Level.OFF);
        BinaryImporter importer = BinaryImporter.getInstance();
        importer.setAssetManager(new DesktopAssetManager(false));
        Spatial root = (Spatial) importer.load(new File(args[0]));
        root.updateGeometricState();
        List<Geometry> geometries = new ArrayList<>();
        root.depthFirstTraversal(s -> {
            if (s instanceof Geometry) {
                geometries.add((Geometry) s);
            }
        });
        long triangles = 0;
        try (PrintWriter out = new PrintWriter(new BufferedWriter(new FileWriter(args[1])))) {
            out.println("# " + args[0] + " via J3oToObj");
            int first = 1;
            Vector3f local = new Vector3f();
            Vector3f world = new Vector3f();
            int[] corner = new int[3];
            for (Geometry g : geometries) {
                Mesh mesh = g.getMesh();
                if (mesh.getMode() != Mesh.Mode.Triangles) {
                    continue;  // strips and fans do not occur in the models used
                }
                out.println("o " + g.getName());
                FloatBuffer positions = (FloatBuffer) mesh.getBuffer(VertexBuffer.Type.Position).getDataReadOnly();
                for (int i = 0; i < mesh.getVertexCount(); i++) {
                    local.set(positions.get(3 * i), positions.get(3 * i + 1), positions.get(3 * i + 2));
                    g.getWorldTransform().transformVector(local, world);
                    out.println("v " + world.x + " " + world.y + " " + world.z);
                }
                for (int i = 0; i < mesh.getTriangleCount(); i++) {
                    mesh.getTriangle(i, corner);
                    out.println("f " + (corner[0] + first) + " " + (corner[1] + first) + " " + (corner[2] + first));
                }
                first += mesh.getVertexCount();
                triangles += mesh.getTriangleCount();
            }
        }
        System.out.println(geometries.size() + " geometries, " + triangles + " triangles");
    }
}
