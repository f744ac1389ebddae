// UnrealHaptics.Scene: a scene built through calls before a session opens it (uh_scene_*): load a
// scene file or the default scene, add objects from a mesh file, a .ist or vertex/index arrays (an
// engine's own mesh), set poses, choose what is watched. Sessions copy the scene when they open.

using System;
using System.Runtime.InteropServices;

namespace UnrealHaptics
{
    /// <summary>The force law (docs/forcecomp.md): minus the gradient of the overlap volume, or the paper's eq. 1.</summary>
    public enum ForceLaw { Gradient = 0, Paper = 1 }

    /// <summary>A tool of a scene: its shape, force law (ForceComp) and device (Haptico).</summary>
    public sealed class ToolSettings
    {
        public string Name = "tool";
        public string MeshPath;              // a closed mesh or a .ist file
        public double MetersPerUnit = 1.0;
        public long Spheres = 10000;
        public bool ThreeDof = false;
        public ForceLaw Law = ForceLaw.Gradient;
        public double Stiffness = 2.0e4;     // gradient law: k [N/m^2] (a 4 mm tip: a 0.5 N/mm spring)
        public double ForceScale = 1.0e7;    // paper law: eps_c [N/m^3]
        public double Damping = 2.0;         // eps_d [N s/m]
        public double MassKg = 0.05;
        public double MaxForceN = 8.0;
        public double MaxTorqueNm = 0.3;
        public string DeviceDriver = "sim-raster";  // sim-line, sim-circle, sim-raster, sim-replay, sim-hand
        public string DeviceConfigJson;      // the driver's settings as a JSON object; null = {}
    }

    public sealed class Scene : IDisposable
    {
        Native.uh_scene_id id_;

        Scene(Native.uh_scene_id id) { id_ = id; }

        /// <summary>A scene file; null: the embedded default scene.</summary>
        public static Scene Load(string scenePath = null)
        {
            Native.uh_scene_id id;
            Native.Check(Native.uh_scene_load(Native.Utf8In(scenePath), out id), "uh_scene_load");
            return new Scene(id);
        }

        internal Native.uh_scene_id Id
        {
            get
            {
                if (id_.bits == 0) throw new ObjectDisposedException("Scene");
                return id_;
            }
        }

        /// <summary>Adds a closed mesh given as arrays: `vertices` x, y, z per vertex (mesh units),
        /// `indices` three per triangle, counter-clockwise seen from outside (a mesh wound the
        /// other way, e.g. Unity's clockwise front faces, is flipped when validated). Returns the
        /// object's index.</summary>
        public int AddMesh(string name, double[] vertices, int[] indices, double[] position, double[] orientation,
                           long spheres = 10000, double metersPerUnit = 1.0, bool watch = true)
        {
            if (vertices == null || indices == null || vertices.Length % 3 != 0 || indices.Length % 3 != 0)
                throw new ArgumentException("vertices and indices must hold whole triples");
            var v = GCHandle.Alloc(vertices, GCHandleType.Pinned);
            var i = GCHandle.Alloc(indices, GCHandleType.Pinned);
            try
            {
                var shape = Shape(spheres, metersPerUnit);
                shape.vertices = v.AddrOfPinnedObject();
                shape.vertex_count = vertices.Length / 3;
                shape.indices = i.AddrOfPinnedObject();
                shape.triangle_count = indices.Length / 3;
                return Add(name, shape, position, orientation, watch);
            }
            finally
            {
                v.Free();
                i.Free();
            }
        }

        /// <summary>Adds an object from a mesh file (packed on first use, cached) or a .ist file.</summary>
        public int AddFile(string name, string path, double[] position, double[] orientation, long spheres = 10000,
                           double metersPerUnit = 1.0, bool watch = true)
        {
            var bytes = Native.Utf8In(path);
            var pin = GCHandle.Alloc(bytes, GCHandleType.Pinned);
            try
            {
                var shape = Shape(spheres, metersPerUnit);
                if (path.EndsWith(".ist", StringComparison.OrdinalIgnoreCase))
                    shape.ist_path = pin.AddrOfPinnedObject();
                else
                    shape.mesh_path = pin.AddrOfPinnedObject();
                return Add(name, shape, position, orientation, watch);
            }
            finally
            {
                pin.Free();
            }
        }

        static Native.uh_shape_def Shape(long spheres, double metersPerUnit)
        {
            var shape = Native.DefaultShapeDef();
            shape.spheres = spheres;
            shape.meters_per_unit = metersPerUnit;
            return shape;
        }

        int Add(string name, Native.uh_shape_def shape, double[] position, double[] orientation, bool watch)
        {
            var bytes = Native.Utf8In(name);
            var pin = GCHandle.Alloc(bytes, GCHandleType.Pinned);
            try
            {
                var def = new Native.uh_object_def();
                def.struct_size = (uint)Marshal.SizeOf(typeof(Native.uh_object_def));
                def.name = pin.AddrOfPinnedObject();
                def.shape = shape;
                def.position = position ?? new double[3];
                def.orientation = orientation ?? new double[] { 1, 0, 0, 0 };
                def.watch = watch ? 1 : 0;
                int index;
                Native.Check(Native.uh_scene_add_object(Id, ref def, out index), "uh_scene_add_object");
                return index;
            }
            finally
            {
                pin.Free();
            }
        }

        /// <summary>Sets the first tool (its mesh or .ist, force law, limits and device); see ToolSettings.</summary>
        public void SetTool(ToolSettings t)
        {
            WithToolDef(t, (ref Native.uh_tool_def def) => Native.Check(Native.uh_scene_set_tool(Id, ref def), "uh_scene_set_tool"));
        }

        /// <summary>Adds a tool after the scene's tools, on its own device; returns its index.</summary>
        public int AddTool(ToolSettings t)
        {
            int index = -1;
            WithToolDef(t, (ref Native.uh_tool_def def) => Native.Check(Native.uh_scene_add_tool(Id, ref def, out index), "uh_scene_add_tool"));
            return index;
        }

        public int ToolCount
        {
            get
            {
                int n;
                Native.Check(Native.uh_scene_tool_count(Id, out n), "uh_scene_tool_count");
                return n;
            }
        }

        delegate void ToolDefUse(ref Native.uh_tool_def def);

        // the tool def of `t`, handed to `use` while the strings it points to are pinned
        static void WithToolDef(ToolSettings t, ToolDefUse use)
        {
            if (t == null || string.IsNullOrEmpty(t.MeshPath)) throw new ArgumentException("the tool needs a mesh or .ist file");
            var pins = new System.Collections.Generic.List<GCHandle>();
            Func<string, IntPtr> pin = text =>
            {
                if (text == null) return IntPtr.Zero;
                var h = GCHandle.Alloc(Native.Utf8In(text), GCHandleType.Pinned);
                pins.Add(h);
                return h.AddrOfPinnedObject();
            };
            try
            {
                var def = Native.DefaultToolDef();
                def.name = pin(t.Name);
                def.shape = Shape(t.Spheres, t.MetersPerUnit);
                if (t.MeshPath.EndsWith(".ist", StringComparison.OrdinalIgnoreCase))
                    def.shape.ist_path = pin(t.MeshPath);
                else
                    def.shape.mesh_path = pin(t.MeshPath);
                def.mode = t.ThreeDof ? 1 : 0;
                def.law = (int)t.Law;
                def.stiffness = t.Stiffness;
                def.force_scale = t.ForceScale;
                def.damping = t.Damping;
                def.mass_kg = t.MassKg;
                def.max_force_n = t.MaxForceN;
                def.max_torque_nm = t.MaxTorqueNm;
                def.device_driver = pin(t.DeviceDriver);
                def.device_config_json = pin(t.DeviceConfigJson);
                use(ref def);
            }
            finally
            {
                foreach (var h in pins) h.Free();
            }
        }

        public void RemoveObject(string name)
        {
            Native.Check(Native.uh_scene_remove_object(Id, Native.Utf8In(name)), "uh_scene_remove_object");
        }

        public void SetPose(string name, double[] position, double[] orientation)
        {
            Native.Check(Native.uh_scene_set_object_pose(Id, Native.Utf8In(name), position, orientation),
                "uh_scene_set_object_pose");
        }

        public void Watch(string name, bool watch)
        {
            Native.Check(Native.uh_scene_watch(Id, Native.Utf8In(name), watch ? 1 : 0), "uh_scene_watch");
        }

        /// <summary>Haptic rate in [1, 10000] Hz; collision rate in [0, 10000] Hz (0 = free-running).</summary>
        public void SetRates(double hapticHz, double collisionHz)
        {
            Native.Check(Native.uh_scene_set_rates(Id, hapticHz, collisionHz), "uh_scene_set_rates");
        }

        public int ObjectCount
        {
            get
            {
                int n;
                Native.Check(Native.uh_scene_object_count(Id, out n), "uh_scene_object_count");
                return n;
            }
        }

        public void Dispose()
        {
            Native.uh_scene_destroy(id_);  // a zero id: nothing
            id_ = new Native.uh_scene_id();
            GC.SuppressFinalize(this);
        }

        ~Scene() { Native.uh_scene_destroy(id_); }
    }
}
