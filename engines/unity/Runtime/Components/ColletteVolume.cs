// ColletteVolume (the paper's ColletteVolume) for Unity: AddCollisionWatcher(a, b) and an
// OnCollision event on the main thread (contact begin and end, with the newest force). Not compiled
// in this repository (UnityEngine).
using System;
using System.Collections.Generic;
using UnityEngine;

namespace UnrealHaptics.Components
{
    public sealed class ColletteVolume : MonoBehaviour
    {
        public HapticManager hapticManager;
        /// <summary>(object, tool, begin?, sphere pairs, overlap volume [m^3], force [N, Unity frame])</summary>
        public event Action<GameObject, GameObject, bool, int, double, Vector3> OnCollision;
        readonly Dictionary<string, KeyValuePair<GameObject, GameObject>> watched_ = new Dictionary<string, KeyValuePair<GameObject, GameObject>>();

        public void AddCollisionWatcher(GameObject a, GameObject b)
        {
            var o = a.GetComponent<ColletteStaticMesh>() != null ? a : b;
            watched_[o.name] = new KeyValuePair<GameObject, GameObject>(o, o == a ? b : a);
        }

        void OnEnable() { hapticManager.OnContact += Contact; }
        void OnDisable() { hapticManager.OnContact -= Contact; }

        void Contact(ContactEvent e, string objectName)
        {
            KeyValuePair<GameObject, GameObject> pair;
            if (OnCollision == null || !watched_.TryGetValue(objectName, out pair)) return;
            var force = hapticManager.Newest != null ? UnityFrame.Direction(hapticManager.Newest.Force) : Vector3.zero;
            OnCollision(pair.Key, pair.Value, e.Kind == ContactKind.Begin, e.Pairs, e.Volume, force);
        }
    }
}
