// UForceComponent (the paper's ForceComponent): the tool's volumetric penalty force law and its
// limits, edited in the details panel; the ForceController hands them to the HapticManager.
#pragma once

#include "CoreMinimal.h"
#include "Components/ActorComponent.h"

#include "ForceComponent.generated.h"

struct FUhToolSpec;

UCLASS(ClassGroup = (Haptics), meta = (BlueprintSpawnableComponent))
class FORCECOMP_API UForceComponent : public UActorComponent
{
	GENERATED_BODY()

public:
	/** The tool's mesh (.obj, .stl, ... or .ist); empty: the scene file's tool and force are kept. */
	UPROPERTY(EditAnywhere, Category = "Force") FFilePath ToolMesh;
	UPROPERTY(EditAnywhere, Category = "Force") double MetersPerUnit = 1.0;
	UPROPERTY(EditAnywhere, Category = "Force") int64 Spheres = 10000;
	/** 3-DOF (force only) instead of 6-DOF (force and torque). */
	UPROPERTY(EditAnywhere, Category = "Force") bool bThreeDof = false;
	/** The force law: minus the gradient of the overlap volume (default) or the paper's eq. 1 (docs/forcecomp.md). */
	UPROPERTY(EditAnywhere, Category = "Force") bool bPaperLaw = false;
	/** Gradient law: stiffness k [N/m^2] (force per unit of contact area); paper law: eps_c [N/m^3]; damping eps_d [N s/m]. */
	UPROPERTY(EditAnywhere, Category = "Force") double Stiffness = 2.0e4;
	UPROPERTY(EditAnywhere, Category = "Force") double ForceScale = 1.0e7;
	UPROPERTY(EditAnywhere, Category = "Force") double Damping = 2.0;
	UPROPERTY(EditAnywhere, Category = "Force") double MassKg = 0.05;
	UPROPERTY(EditAnywhere, Category = "Force") double MaxForceN = 8.0;
	UPROPERTY(EditAnywhere, Category = "Force") double MaxTorqueNm = 0.3;
	/** The device: a libuh driver ("sim-raster", "sim-line", "sim-hand", ...) and its JSON settings. */
	UPROPERTY(EditAnywhere, Category = "Force") FString DeviceDriver = TEXT("sim-raster");
	UPROPERTY(EditAnywhere, Category = "Force") FString DeviceConfigJson;

	FUhToolSpec ToolSpec() const;
};
