// UnrealHaptics.Session: a haptic session of libuh for managed code (Unity's scripts, any .NET
// program). Open a scene (or the default one), Start() the haptic and collision threads, Poll() the
// newest state from any thread, PollEvent() contact events on the owner thread, Stop() for the
// report; Dispose() always stops (zero force, every thread joined), also from the finalizer.

using System;
using System.Runtime.InteropServices;
using System.Threading;

namespace UnrealHaptics
{
    /// <summary>The newest state of a session, as its haptic thread sent it in its last tick.</summary>
    public sealed class State
    {
        public double TimeS;                                 // that tick's time since start [s]
        public double[] ToolPosition = new double[3];        // the tool's mesh frame origin, world [m]
        public double[] ToolOrientation = new double[4];     // (w, x, y, z)
        public double[] Force = new double[3];               // sent to the device, world [N]
        public double[] Torque = new double[3];              // [N m]
        public int ContactPairs;                             // sphere pairs the force used
        public ulong HapticTicks;
        public ulong MissedDeadlines;
        public double HapticRateHz;                          // over the last ~100 ms
        public double CollisionRateHz;
        public uint Buttons;  // the device's buttons (bit i: button i)
    }

    public enum ContactKind { Begin = Native.UH_CONTACT_BEGIN, End = Native.UH_CONTACT_END }

    /// <summary>A contact between a tool and a watched object began or ended.</summary>
    public struct ContactEvent
    {
        public ContactKind Kind;
        public int Object;        // the object's index in the scene
        public int Tool;          // the tool's index in the scene
        public double TimeS;      // of the collision step that saw it [s]
        public double Volume;     // overlap volume then [m^3] (0 for End; 0 through the proxy)
        public int Pairs;         // overlapping sphere pairs then
    }

    public sealed class Session : IDisposable
    {
        // the native session's id; zero once destroyed (uh_session_destroy stops it first), by
        // Dispose() or, when that was never called, by the finaliser
        long id_;
        // the tick counter the haptic-thread callback writes (through a GCHandle as its user pointer)
        sealed class TickCounter { public long Ticks; }
        readonly TickCounter counter_ = new TickCounter();
        GCHandle counterHandle_;
        static readonly Native.uh_tick_fn TickCallback = OnTick;  // kept alive for the process

        Session(Native.uh_session_id id) { id_ = unchecked((long)id.bits); }

        /// <summary>Opens a session of a scene file (docs/scenes.md); null: the embedded default
        /// scene (the bunny explored by a simulated stylus). Loads or builds the trees and opens the
        /// device; starts no thread.</summary>
        public static Session Open(string scenePath = null)
        {
            CheckVersion();
            Native.uh_session_id id;
            var status = Native.uh_session_open_checked(Native.ApiVersion, Native.Utf8In(scenePath), out id);
            return Adopt(status, id, "uh_session_open");
        }

        /// <summary>Opens a session of a scene built through calls (see Scene).</summary>
        public static Session Create(Scene scene, string cacheDir = null)
        {
            CheckVersion();
            var def = Native.DefaultSessionDef();
            var cache = Native.Utf8In(cacheDir);
            var pin = cache != null ? GCHandle.Alloc(cache, GCHandleType.Pinned) : default(GCHandle);
            try
            {
                def.cache_dir = cache != null ? pin.AddrOfPinnedObject() : IntPtr.Zero;
                Native.uh_session_id id;
                var status = Native.uh_session_create_checked(Native.ApiVersion, scene.Id, ref def, out id);
                return Adopt(status, id, "uh_session_create");
            }
            finally
            {
                if (pin.IsAllocated) pin.Free();
            }
        }

        static Session Adopt(int status, Native.uh_session_id id, string call)
        {
            if (status != Native.UH_OK) throw new UhException(status, call, Native.LastError());
            return new Session(id);
        }

        static void CheckVersion()
        {
            var library = Native.uh_api_version();
            if (library != Native.ApiVersion)
                throw new UhException(Native.UH_ERROR_VERSION, "open",
                    "libuh speaks API version " + library + ", this binding version " + Native.ApiVersion);
        }

        Native.uh_session_id Raw
        {
            get
            {
                var id = Interlocked.Read(ref id_);
                if (id == 0) throw new ObjectDisposedException("Session");
                return new Native.uh_session_id { bits = unchecked((ulong)id) };
            }
        }

        // destroys the native session once, whoever calls first (Dispose or the finaliser)
        void Destroy()
        {
            var id = Interlocked.Exchange(ref id_, 0);
            if (id != 0) Native.uh_session_destroy(new Native.uh_session_id { bits = unchecked((ulong)id) });
        }

        /// <summary>Counts the haptic thread's ticks (TickCallbacks) through a native callback on
        /// that thread. Only before Start() or RunStepped().</summary>
        public void CountTicks()
        {
            if (!counterHandle_.IsAllocated) counterHandle_ = GCHandle.Alloc(counter_);
            Native.Check(Native.uh_session_set_tick_callback(Raw, TickCallback, GCHandle.ToIntPtr(counterHandle_)),
                "uh_session_set_tick_callback");
        }

        /// <summary>Ticks the haptic-thread callback saw (after CountTicks()). Any thread.</summary>
        public long TickCallbacks { get { return Interlocked.Read(ref counter_.Ticks); } }

        // On the haptic thread, every tick: real-time, so it only counts (no allocation, no lock).
        [MonoPInvokeCallback(typeof(Native.uh_tick_fn))]
        static void OnTick(IntPtr user, IntPtr state)
        {
            var counter = (TickCounter)GCHandle.FromIntPtr(user).Target;
            Interlocked.Increment(ref counter.Ticks);
        }

        /// <summary>Starts the haptic, collision and monitor threads; returns at once.</summary>
        public void Start() { Native.Check(Native.uh_session_start(Raw), "uh_session_start"); }

        /// <summary>Runs `seconds` of the session on this thread in simulated time (deterministic),
        /// then stops it. Instead of Start().</summary>
        public void RunStepped(double seconds, int ticksPerCollisionStep)
        {
            Native.Check(Native.uh_session_run_stepped(Raw, seconds, ticksPerCollisionStep), "uh_session_run_stepped");
        }

        /// <summary>The newest state (zeros before the first tick; after Stop(), the last one with
        /// the zero force the device got). Any thread; never waits for the haptic thread.</summary>
        public State Poll()
        {
            var s = new Native.uh_state();
            s.struct_size = (uint)Marshal.SizeOf(typeof(Native.uh_state));
            Native.Check(Native.uh_session_poll(Raw, ref s), "uh_session_poll");
            var o = new State();
            o.TimeS = s.time_s;
            Array.Copy(s.tool_position, o.ToolPosition, 3);
            Array.Copy(s.tool_orientation, o.ToolOrientation, 4);
            Array.Copy(s.force, o.Force, 3);
            Array.Copy(s.torque, o.Torque, 3);
            o.ContactPairs = s.contact_pairs;
            o.HapticTicks = s.haptic_ticks;
            o.MissedDeadlines = s.missed_deadlines;
            o.HapticRateHz = s.haptic_rate_hz;
            o.CollisionRateHz = s.collision_rate_hz;
            o.Buttons = s.buttons;
            return o;
        }

        /// <summary>The oldest contact event not yet taken; false when none waits. Owner thread.</summary>
        public bool PollEvent(out ContactEvent e)
        {
            var n = new Native.uh_contact_event();
            n.struct_size = (uint)Marshal.SizeOf(typeof(Native.uh_contact_event));
            int has;
            Native.Check(Native.uh_session_poll_event(Raw, ref n, out has), "uh_session_poll_event");
            e = new ContactEvent { Kind = (ContactKind)n.kind, Object = n.@object, Tool = n.tool, TimeS = n.time_s, Volume = n.volume, Pairs = n.pairs };
            return has != 0;
        }

        /// <summary>Moves scene object `index` while the session runs (world [m], (w, x, y, z)).</summary>
        public void SetObjectPose(int index, double[] position, double[] orientation)
        {
            Native.Check(Native.uh_session_set_object_pose(Raw, index, position, orientation), "uh_session_set_object_pose");
        }

        public int ObjectCount
        {
            get
            {
                int n;
                Native.Check(Native.uh_session_object_count(Raw, out n), "uh_session_object_count");
                return n;
            }
        }

        public string ObjectName(int index)
        {
            IntPtr name;
            Native.Check(Native.uh_session_object_name(Raw, index, out name), "uh_session_object_name");
            return Native.Utf8Out(name);
        }

        /// <summary>True when the running session ended by itself: a device faulted, or a libuh
        /// thread ended (every device was sent zero at its next tick); Stop() then throws the cause.
        /// False while it runs as it should, before Start() and after Stop(). Owner thread.</summary>
        public bool EndedByItself
        {
            get
            {
                int ended;
                Native.Check(Native.uh_session_ended(Raw, out ended), "uh_session_ended");
                return ended != 0;
            }
        }

        /// <summary>Sends zero force at once, stops and joins every thread and returns the report
        /// (the JSON object `uh run --json` prints). Idempotent. Throws if a thread had ended on its
        /// own (the session is stopped all the same).</summary>
        public string Stop()
        {
            var status = Native.uh_session_stop(Raw);
            var error = status != Native.UH_OK ? Native.LastError() : null;
            IntPtr json;
            var reported = Native.uh_session_report_json(Raw, out json);
            if (status != Native.UH_OK) throw new UhException(status, "uh_session_stop", error);
            if (reported != Native.UH_OK) return null;  // stopped before it started: no report
            return Native.Utf8Out(json);
        }

        /// <summary>Stops (zero force, threads joined) and frees the session. Safe twice.</summary>
        public void Dispose()
        {
            Destroy();
            // the haptic thread is joined: the callback's user pointer is no longer used
            if (counterHandle_.IsAllocated) counterHandle_.Free();
            GC.SuppressFinalize(this);
        }

        ~Session()
        {
            // the counter handle is freed only once no haptic thread can call back (after the destroy)
            Destroy();
            if (counterHandle_.IsAllocated) counterHandle_.Free();
        }
    }
}
