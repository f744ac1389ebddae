// ForceController (the paper's ForceController) for Unity: reports the force and torque sent to the device
// each frame (ForceOnHapticTick, main thread); the force itself is computed by libuh on its haptic
// thread. Not compiled in this repository (UnityEngine).
using System;
using UnityEngine;

namespace UnrealHaptics.Components
{
    public sealed class ForceController : MonoBehaviour
    {
        public HapticManager hapticManager;
        public ForceComponent forceComponent;
        public event Action<Vector3, Vector3> ForceOnHapticTick;

        void Awake() { if (forceComponent != null) hapticManager.SetTool(forceComponent); }
        void OnEnable() { hapticManager.ForceOnHapticTick += Forward; }
        void OnDisable() { hapticManager.ForceOnHapticTick -= Forward; }

        void Forward(Vector3 force, Vector3 torque)
        {
            if (ForceOnHapticTick != null) ForceOnHapticTick(force, torque);
        }
    }
}
