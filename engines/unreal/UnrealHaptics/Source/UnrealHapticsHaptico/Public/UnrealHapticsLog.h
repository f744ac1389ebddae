// The plugin's log category: every module logs to LogUnrealHaptics (loading libuh, the session,
// registrations refused, meshes that cannot be read). Verbose adds where libuh was looked for.
#pragma once

#include "CoreMinimal.h"

UNREALHAPTICSHAPTICO_API DECLARE_LOG_CATEGORY_EXTERN(LogUnrealHaptics, Log, All);
