#include "Modules/ModuleManager.h"
#include "UnrealHapticsLog.h"

DEFINE_LOG_CATEGORY(LogUnrealHaptics);

IMPLEMENT_MODULE(FDefaultModuleImpl, UnrealHapticsHaptico)
