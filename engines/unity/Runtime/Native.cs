// UnrealHaptics.Native: the C API of libuh (include/uh/uh.h) for P/Invoke, one declaration per C
// function, the structs laid out as in C (sequential, natural alignment, struct_size first).
// Strings cross as NUL-terminated UTF-8 both ways (Utf8In / Utf8Out), whatever the platform's
// ANSI code page. Callbacks the library calls are static methods marked [MonoPInvokeCallback] (Mono's
// and IL2CPP's AOT rules: no instance delegates, no closures), and get their object back through
// the void* user pointer (a GCHandle). Ids (uh_scene_id, uh_session_id, uh_tree_id) are 64-bit
// values passed by value, never addresses. Structs grow at their end from one version to the next:
// each is passed with its own Marshal.SizeOf as struct_size, and its defaults come from the
// library's uh_X_init (the header's uh_default_X() are inline C). Managed code should use Session
// and Scene, not this class.

using System;
using System.Runtime.InteropServices;
using System.Text;

namespace UnrealHaptics
{
    /// <summary>Marks a static method that native code calls back (Mono / IL2CPP AOT). Defined here
    /// so that the assembly needs no Unity reference; Mono matches the attribute by name.</summary>
    [AttributeUsage(AttributeTargets.Method)]
    public sealed class MonoPInvokeCallbackAttribute : Attribute
    {
        public MonoPInvokeCallbackAttribute(Type delegateType) { DelegateType = delegateType; }
        public Type DelegateType { get; private set; }
    }

    public static class Native
    {
        /// <summary>libuh: libuh.so (Linux), uh.dll (Windows, the mingw-w64 build), libuh.dylib.</summary>
        public const string Library = "uh";
        /// <summary>The UH_API_VERSION this binding was written for; checked at open.</summary>
        public const int ApiVersion = 2;

        public const int UH_OK = 0;
        public const int UH_ERROR_INVALID_ARGUMENT = 1;
        public const int UH_ERROR_STALE_HANDLE = 2;
        public const int UH_ERROR_WRONG_STATE = 3;
        public const int UH_ERROR_VERSION = 4;
        public const int UH_ERROR_INTERNAL = 6;
        public const int UH_ERROR_FILE = 7;
        public const int UH_ERROR_MESH = 8;
        public const int UH_ERROR_DEVICE = 9;
        public const int UH_ERROR_THREAD = 10;
        public const int UH_ERROR_BUSY = 11;
        public const int UH_CONTACT_BEGIN = 0;
        public const int UH_CONTACT_END = 1;

        [StructLayout(LayoutKind.Sequential)] public struct uh_tree_id { public ulong bits; }
        [StructLayout(LayoutKind.Sequential)] public struct uh_scene_id { public ulong bits; }
        [StructLayout(LayoutKind.Sequential)] public struct uh_session_id { public ulong bits; }

        [StructLayout(LayoutKind.Sequential)]
        public struct uh_state
        {
            public uint struct_size;
            public double time_s;
            [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] tool_position;
            [MarshalAs(UnmanagedType.ByValArray, SizeConst = 4)] public double[] tool_orientation;
            [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] force;
            [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] torque;
            public int contact_pairs;
            public ulong haptic_ticks;
            public ulong missed_deadlines;
            public double haptic_rate_hz;
            public double collision_rate_hz;
            public uint buttons;
        }

        [StructLayout(LayoutKind.Sequential)]
        public struct uh_contact_event
        {
            public uint struct_size;
            public int kind;
            public int @object;
            public double time_s;
            public double volume;
            public int pairs;
            public int tool;                    // the tool's index in the scene
        }

        [StructLayout(LayoutKind.Sequential)]
        public struct uh_shape_def
        {
            public uint struct_size;
            public IntPtr mesh_path;
            public IntPtr ist_path;
            public uh_tree_id tree;
            public IntPtr vertices;
            public int vertex_count;
            public IntPtr indices;
            public int triangle_count;
            public long spheres;
            public double meters_per_unit;
        }

        [StructLayout(LayoutKind.Sequential)]
        public struct uh_object_def
        {
            public uint struct_size;
            public IntPtr name;
            public uh_shape_def shape;
            [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] position;
            [MarshalAs(UnmanagedType.ByValArray, SizeConst = 4)] public double[] orientation;
            public int watch;
        }

        // the arrays of uh_tool_def as scalar fields, so that the struct stays blittable (filled by
        // uh_tool_def_init through a reference)
        [StructLayout(LayoutKind.Sequential)]
        public struct uh_tool_def
        {
            public uint struct_size;
            public IntPtr name;
            public uh_shape_def shape;
            public int mode;
            public int law;                     // 0 gradient (default), 1 paper
            public double stiffness;            // gradient law: k [N/m^2]
            public double force_scale;          // paper law: eps_c [N/m^3]
            public double damping;
            public double damping_full_volume;
            public double mass_kg;
            public double center_of_mass_x, center_of_mass_y, center_of_mass_z;
            public double max_force_n;
            public double max_torque_nm;
            public IntPtr device_driver;
            public IntPtr device_config_json;
            public double workspace_scale;
            public double workspace_offset_x, workspace_offset_y, workspace_offset_z;
            public double workspace_rotation_w, workspace_rotation_x, workspace_rotation_y, workspace_rotation_z;
            public double tool_offset_x, tool_offset_y, tool_offset_z;  // the tool's origin in the handle frame [m]
        }

        [StructLayout(LayoutKind.Sequential)]
        public struct uh_session_def
        {
            public uint struct_size;
            public double haptic_hz;
            public double collision_hz;
            public int raise_priority;
            public IntPtr cache_dir;
        }

        /// <summary>uh_tick_fn: called on the haptic thread after every tick (real-time).</summary>
        [UnmanagedFunctionPointer(CallingConvention.Cdecl)]
        public delegate void uh_tick_fn(IntPtr user, IntPtr state);

        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern IntPtr uh_version_string();
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_api_version();
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern IntPtr uh_last_error();
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern IntPtr uh_status_name(int status);

        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_shape_def_init(ref uh_shape_def def);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_tool_def_init(ref uh_tool_def def);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_def_init(ref uh_session_def def);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_is_valid(uh_scene_id scene);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_load(byte[] scene_path, out uh_scene_id scene);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_create(byte[] name, out uh_scene_id scene);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern void uh_scene_destroy(uh_scene_id scene);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_add_object(uh_scene_id scene, ref uh_object_def def, out int index);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_remove_object(uh_scene_id scene, byte[] name);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_set_object_pose(uh_scene_id scene, byte[] name, double[] position, double[] orientation);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_watch(uh_scene_id scene, byte[] name, int watch);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_set_tool(uh_scene_id scene, ref uh_tool_def def);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_add_tool(uh_scene_id scene, ref uh_tool_def def, out int index);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_remove_tool(uh_scene_id scene, byte[] name);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_tool_count(uh_scene_id scene, out int count);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_set_rates(uh_scene_id scene, double haptic_hz, double collision_hz);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_scene_object_count(uh_scene_id scene, out int count);

        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_is_valid(uh_session_id session);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_open_checked(int api_version, byte[] scene_path, out uh_session_id session);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_create_checked(int api_version, uh_scene_id scene, ref uh_session_def def, out uh_session_id session);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_start(uh_session_id session);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_run_stepped(uh_session_id session, double seconds, int ticks_per_collision_step);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_poll(uh_session_id session, ref uh_state state);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_poll_event(uh_session_id session, ref uh_contact_event e, out int has_event);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_set_object_pose(uh_session_id session, int @object, double[] position, double[] orientation);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_set_tick_callback(uh_session_id session, uh_tick_fn fn, IntPtr user);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_ended(uh_session_id session, out int ended);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_stop(uh_session_id session);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_report_json(uh_session_id session, out IntPtr json);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_object_count(uh_session_id session, out int count);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_object_name(uh_session_id session, int @object, out IntPtr name);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern int uh_session_tool_count(uh_session_id session, out int count);
        [DllImport(Library, CallingConvention = CallingConvention.Cdecl)] public static extern void uh_session_destroy(uh_session_id session);

        /// <summary>The library's defaults of a shape, a tool and a session's settings, for this
        /// binding's struct layouts (uh.h's inline uh_default_*()).</summary>
        public static uh_shape_def DefaultShapeDef()
        {
            var def = new uh_shape_def();
            def.struct_size = (uint)Marshal.SizeOf(typeof(uh_shape_def));
            Check(uh_shape_def_init(ref def), "uh_shape_def_init");
            return def;
        }

        public static uh_tool_def DefaultToolDef()
        {
            var def = new uh_tool_def();
            def.struct_size = (uint)Marshal.SizeOf(typeof(uh_tool_def));
            Check(uh_tool_def_init(ref def), "uh_tool_def_init");
            return def;
        }

        public static uh_session_def DefaultSessionDef()
        {
            var def = new uh_session_def();
            def.struct_size = (uint)Marshal.SizeOf(typeof(uh_session_def));
            Check(uh_session_def_init(ref def), "uh_session_def_init");
            return def;
        }

        /// <summary>A NUL-terminated UTF-8 copy of `s` (null stays null: NULL for the C API).</summary>
        public static byte[] Utf8In(string s)
        {
            if (s == null) return null;
            var bytes = new byte[Encoding.UTF8.GetByteCount(s) + 1];
            Encoding.UTF8.GetBytes(s, 0, s.Length, bytes, 0);
            return bytes;
        }

        /// <summary>The NUL-terminated UTF-8 text at `p` ("" for NULL).</summary>
        public static string Utf8Out(IntPtr p)
        {
            if (p == IntPtr.Zero) return "";
            int n = 0;
            while (Marshal.ReadByte(p, n) != 0) ++n;
            var bytes = new byte[n];
            Marshal.Copy(p, bytes, 0, n);
            return Encoding.UTF8.GetString(bytes);
        }

        /// <summary>The calling thread's last error message from the library.</summary>
        public static string LastError() { return Utf8Out(uh_last_error()); }

        /// <summary>Throws UhException for a failed call, with the library's message.</summary>
        public static void Check(int status, string call)
        {
            if (status != UH_OK) throw new UhException(status, call, LastError());
        }
    }

    /// <summary>A failed C API call: its status (Native.UH_ERROR_*) and the library's message, which
    /// names what was wrong (a file, a field, a handle).</summary>
    public sealed class UhException : Exception
    {
        public UhException(int status, string call, string message)
            : base(call + ": " + Native.Utf8Out(Native.uh_status_name(status)) + ": " + message)
        {
            Status = status;
        }
        public int Status { get; private set; }
    }
}
