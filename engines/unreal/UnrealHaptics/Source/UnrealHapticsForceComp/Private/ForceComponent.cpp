#include "ForceComponent.h"

#include "UhPaths.h"
#include "UhTypes.h"

FUhToolSpec UForceComponent::ToolSpec() const
{
	FUhToolSpec Spec;
	Spec.MeshPath = UhPaths::ResolveProjectFile(ToolMesh.FilePath);
	Spec.MetersPerUnit = MetersPerUnit;
	Spec.Spheres = Spheres;
	Spec.bThreeDof = bThreeDof;
	Spec.bPaperLaw = bPaperLaw;
	Spec.Stiffness = Stiffness;
	Spec.ForceScale = ForceScale;
	Spec.Damping = Damping;
	Spec.MassKg = MassKg;
	Spec.MaxForceN = MaxForceN;
	Spec.MaxTorqueNm = MaxTorqueNm;
	Spec.DeviceDriver = DeviceDriver;
	Spec.DeviceConfigJson = DeviceConfigJson;
	return Spec;
}
