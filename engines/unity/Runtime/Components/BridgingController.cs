// BridgingController (the paper's BridgingController) for Unity: the tool GameObject follows the
// device every frame (the newest state). Not compiled in this repository (UnityEngine).
using UnityEngine;

namespace UnrealHaptics.Components
{
    public sealed class BridgingController : MonoBehaviour
    {
        public HapticManager hapticManager;
        public Transform tool;

        void OnEnable() { hapticManager.MoveOnHapticTick += Move; }
        void OnDisable() { hapticManager.MoveOnHapticTick -= Move; }

        void Move(Vector3 position, Quaternion rotation, uint buttons)
        {
            if (tool != null) tool.SetPositionAndRotation(position, rotation);
        }
    }
}
