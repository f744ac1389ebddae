// HapticManager (the paper's HapticManager) for Unity: opens a libuh session of the scene file (or
// the default scene) plus the ColletteStaticMeshes registered in Awake/OnEnable, starts it in
// Start(), reads the newest state every frame and stops it in OnDisable/OnDestroy (Dispose: zero
// force, every thread joined). Not compiled in this repository (it needs UnityEngine); thin over
// Session and Scene, which are.
using System;
using System.Collections.Generic;
using UnityEngine;

namespace UnrealHaptics.Components
{
    public sealed class HapticManager : MonoBehaviour
    {
        [Tooltip("A scene file; empty: libuh's default scene (the bunny explored by a simulated stylus)")]
        public string scenePath = "";
        [Tooltip("Objects of the scene file that the Unity scene's ColletteStaticMeshes replace")]
        public string[] sceneObjectsToRemove = { "bunny" };

        /// <summary>Every frame with the newest state: tool position (Unity frame), rotation and the
        /// device's buttons (bit i: button i), as the paper's MoveOnHapticTick.</summary>
        public event Action<Vector3, Quaternion, uint> MoveOnHapticTick;
        /// <summary>Every frame with the newest force [N] and torque [N m] sent to the device (Unity
        /// frame), as the paper's ForceOnHapticTick. They are computed by libuh on its haptic thread.</summary>
        public event Action<Vector3, Vector3> ForceOnHapticTick;
        public event Action<ContactEvent, string> OnContact;

        public State Newest { get; private set; }
        public Session Session { get { return session_; } }

        readonly List<ColletteStaticMesh> objects_ = new List<ColletteStaticMesh>();
        Session session_;

        ForceComponent tool_;

        public void Register(ColletteStaticMesh mesh) { if (!objects_.Contains(mesh)) objects_.Add(mesh); }
        public void SetTool(ForceComponent tool) { tool_ = tool; }

        void Start()
        {
            using (var scene = Scene.Load(string.IsNullOrEmpty(scenePath) ? null : scenePath))
            {
                if (tool_ != null && !string.IsNullOrEmpty(tool_.toolMeshPath)) scene.SetTool(tool_.Settings());
                foreach (var o in objects_) o.AddTo(scene);
                if (objects_.Count > 0)
                    foreach (var name in sceneObjectsToRemove) scene.RemoveObject(name);
                session_ = Session.Create(scene);
            }
            session_.Start();
        }

        void Update()
        {
            if (session_ == null) return;
            Newest = session_.Poll();
            if (MoveOnHapticTick != null)
                MoveOnHapticTick(UnityFrame.Position(Newest.ToolPosition), UnityFrame.Rotation(Newest.ToolOrientation),
                                 Newest.Buttons);
            if (ForceOnHapticTick != null)
                ForceOnHapticTick(UnityFrame.Direction(Newest.Force), UnityFrame.Axial(Newest.Torque));
            ContactEvent e;
            while (session_.PollEvent(out e))
                if (OnContact != null) OnContact(e, session_.ObjectName(e.Object));
            // a device fault or a libuh thread that ended zeroed the force already: stop, and say why
            if (session_.EndedByItself)
            {
                try { StopHaptics(); }
                catch (UhException ex) { Debug.LogError("UnrealHaptics: the session ended by itself: " + ex.Message); }
            }
        }

        void OnDisable() { StopHaptics(); }
        void OnDestroy() { StopHaptics(); }

        /// <summary>Stops (zero force, threads joined) and frees the session; returns the report.</summary>
        public string StopHaptics()
        {
            if (session_ == null) return null;
            string report = null;
            try { report = session_.Stop(); }
            finally
            {
                session_.Dispose();
                session_ = null;
            }
            return report;
        }
    }

    /// <summary>Unity's frame (metres, left-handed, Y up) to libuh's (right-handed): Z is mirrored.</summary>
    public static class UnityFrame
    {
        public static double[] ToUh(Vector3 p) { return new double[] { p.x, p.y, -p.z }; }
        public static double[] ToUh(Quaternion q) { return new double[] { q.w, -q.x, -q.y, q.z }; }
        public static Vector3 Position(double[] p) { return new Vector3((float)p[0], (float)p[1], (float)-p[2]); }
        public static Vector3 Direction(double[] f) { return new Vector3((float)f[0], (float)f[1], (float)-f[2]); }
        /// <summary>An axial vector (torque, angular velocity) flips with the mirror: x and y change sign.</summary>
        public static Vector3 Axial(double[] t) { return new Vector3((float)-t[0], (float)-t[1], (float)t[2]); }
        public static Quaternion Rotation(double[] q) { return new Quaternion((float)-q[1], (float)-q[2], (float)q[3], (float)q[0]); }
    }
}
