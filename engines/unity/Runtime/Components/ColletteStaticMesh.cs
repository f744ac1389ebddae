// ColletteStaticMesh (the paper's ColletteStaticMeshActor) for Unity: this GameObject's MeshFilter
// mesh (through its lossy scale) becomes a collision object of the HapticManager's session; while
// the session runs, its pose follows the transform. Not compiled in this repository (UnityEngine).
using UnityEngine;

namespace UnrealHaptics.Components
{
    [RequireComponent(typeof(MeshFilter))]
    public sealed class ColletteStaticMesh : MonoBehaviour
    {
        public HapticManager hapticManager;
        public long spheres = 10000;
        public bool watch = true;
        int index_ = -1;

        void Awake() { hapticManager.Register(this); }

        internal void AddTo(Scene scene)
        {
            var mesh = GetComponent<MeshFilter>().sharedMesh;
            var scale = transform.lossyScale;
            var v = mesh.vertices;
            var vertices = new double[v.Length * 3];
            for (int i = 0; i < v.Length; ++i)
            {
                var p = UnityFrame.ToUh(Vector3.Scale(v[i], scale));
                vertices[3 * i] = p[0]; vertices[3 * i + 1] = p[1]; vertices[3 * i + 2] = p[2];
            }
            // mirrored: Unity's clockwise faces come out counter-clockwise, as libuh wants them
            index_ = scene.AddMesh(name, vertices, mesh.triangles, UnityFrame.ToUh(transform.position),
                                   UnityFrame.ToUh(transform.rotation), spheres, 1.0, watch);
        }

        void Update()
        {
            var session = hapticManager.Session;
            if (session != null && index_ >= 0 && transform.hasChanged)
            {
                transform.hasChanged = false;
                session.SetObjectPose(index_, UnityFrame.ToUh(transform.position), UnityFrame.ToUh(transform.rotation));
            }
        }
    }
}
