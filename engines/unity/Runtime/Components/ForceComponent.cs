// ForceComponent (the paper's ForceComponent) for Unity: the tool's mesh, force law, limits and
// device as inspector fields; the HapticManager sets them as the scene's tool (Scene.SetTool).
// Not compiled in this repository (it needs UnityEngine); ToolSettings, which it fills, is.
using UnityEngine;

namespace UnrealHaptics.Components
{
    public sealed class ForceComponent : MonoBehaviour
    {
        [Tooltip("The tool's mesh (.obj, .stl, ...) or .ist file")] public string toolMeshPath = "";
        public double metersPerUnit = 1.0;
        public long spheres = 10000;
        public bool threeDof = false;
        [Tooltip("Force law: Gradient (default) or Paper (eq. 1)")] public ForceLaw law = ForceLaw.Gradient;
        [Tooltip("Gradient law: stiffness k [N/m^2], force per unit of contact area")] public double stiffness = 2.0e4;
        [Tooltip("Paper law: penalty stiffness eps_c [N/m^3]")] public double forceScale = 1.0e7;
        [Tooltip("Damping eps_d [N s/m]")] public double damping = 2.0;
        public double massKg = 0.05;
        public double maxForceN = 8.0;
        public double maxTorqueNm = 0.3;
        public string deviceDriver = "sim-raster";
        [TextArea] public string deviceConfigJson = "";

        public ToolSettings Settings()
        {
            return new ToolSettings
            {
                Name = name, MeshPath = toolMeshPath, MetersPerUnit = metersPerUnit, Spheres = spheres,
                ThreeDof = threeDof, Law = law, Stiffness = stiffness, ForceScale = forceScale, Damping = damping,
                MassKg = massKg, MaxForceN = maxForceN, MaxTorqueNm = maxTorqueNm, DeviceDriver = deviceDriver,
                DeviceConfigJson = string.IsNullOrEmpty(deviceConfigJson) ? null : deviceConfigJson,
            };
        }
    }
}
