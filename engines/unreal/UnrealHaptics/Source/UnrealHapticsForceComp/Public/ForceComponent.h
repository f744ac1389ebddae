// UForceComponent (the paper's ForceComponent): the tool's volumetric penalty force law and its
// limits, edited in the details panel; the ForceController hands them to the HapticManager.
#pragma once

#include "CoreMinimal.h"
#include "Components/ActorComponent.h"

#include "ForceComponent.generated.h"

struct FUhToolSpec;

UCLASS(ClassGroup = (Haptics), meta = (BlueprintSpawnableComponent))
class UNREALHAPTICSFORCECOMP_API UForceComponent : public UActorComponent
{
	GENERATED_BODY()

public:
	/** The tool's mesh (.obj, .stl, ... or .ist), relative to the project folder; empty: the scene
	 *  file's tool and force settings are kept (and the settings below are not used). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (FilePathFilter = "Tool mesh (*.obj;*.stl;*.ply;*.off;*.ist)|*.obj;*.stl;*.ply;*.off;*.ist", RelativeToGameDir))
	FFilePath ToolMesh;
	/** The tool mesh's length unit. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (ClampMin = "0.000001", Units = "m"))
	double MetersPerUnit = 1.0;
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (ClampMin = "100", ClampMax = "1000000", UIMax = "100000"))
	int64 Spheres = 10000;
	/** 3-DOF (force only) instead of 6-DOF (force and torque). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force") bool bThreeDof = false;
	/** The force law: minus the gradient of the overlap volume (default) or the paper's eq. 1 (docs/forcecomp.md). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force") bool bPaperLaw = false;
	/** Gradient law: stiffness k [N/m^2] (force per unit of contact area). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (EditCondition = "!bPaperLaw", ClampMin = "0"))
	double Stiffness = 2.0e4;
	/** Paper law: eps_c [N/m^3] (force per overlap volume). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (EditCondition = "bPaperLaw", ClampMin = "0"))
	double ForceScale = 1.0e7;
	/** Damping eps_d [N s/m]. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (ClampMin = "0"))
	double Damping = 2.0;
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (ClampMin = "0.001", Units = "kg"))
	double MassKg = 0.05;
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (ClampMin = "0", Units = "N"))
	double MaxForceN = 8.0;
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (ClampMin = "0"))
	double MaxTorqueNm = 0.3;  // [N m]
	/** The device: a libuh driver ("sim-raster", "sim-line", "sim-hand", ...) and its JSON settings. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force") FString DeviceDriver = TEXT("sim-raster");
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Force", meta = (MultiLine = true)) FString DeviceConfigJson;

	FUhToolSpec ToolSpec() const;
};
