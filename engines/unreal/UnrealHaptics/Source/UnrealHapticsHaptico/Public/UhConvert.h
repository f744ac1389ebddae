// Unreal's frame (centimetres, left-handed, Z up) to libuh's (metres, right-handed): Y is mirrored.
// A mirror reverses triangle winding; libuh flips a mesh wound the wrong way when it validates it.
#pragma once

#include "CoreMinimal.h"

namespace UhConvert
{
	constexpr double MetersPerUnrealUnit = 0.01;

	inline void Position(const FVector& P, double Out[3])
	{
		Out[0] = P.X * MetersPerUnrealUnit;
		Out[1] = -P.Y * MetersPerUnrealUnit;
		Out[2] = P.Z * MetersPerUnrealUnit;
	}

	// Mirroring Y maps the rotation (w, x, y, z) to (w, -x, y, -z).
	inline void Orientation(const FQuat& Q, double Out[4])
	{
		Out[0] = Q.W;
		Out[1] = -Q.X;
		Out[2] = Q.Y;
		Out[3] = -Q.Z;
	}

	inline FVector ToUnrealPosition(const double P[3])
	{
		return FVector(P[0], -P[1], P[2]) / MetersPerUnrealUnit;
	}

	inline FQuat ToUnrealOrientation(const double Q[4])
	{
		return FQuat(-Q[1], Q[2], -Q[3], Q[0]);
	}

	// A force or torque direction (no unit change for N / N m; torque is an axial vector, so
	// mirroring flips its X and Z instead of its Y).
	inline FVector ToUnrealForce(const double F[3]) { return FVector(F[0], -F[1], F[2]); }
	inline FVector ToUnrealTorque(const double T[3]) { return FVector(-T[0], T[1], -T[2]); }
}
