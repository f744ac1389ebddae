"""The Unreal plugin's files, checked without Unreal: stages a copy of the plugin with its own
stage-libuh.sh from this build, then checks that

- the .uplugin is valid JSON with the fields Unreal reads, and names exactly the modules under
  Source/ (ThirdParty aside), each with <Name>/<Name>.Build.cs declaring class <Name>, an
  IMPLEMENT_MODULE(..., <Name>) and, for its public headers, the <NAME>_API macro;
- every plugin module a Build.cs depends on exists, and every header a source file includes from
  the plugin is reachable through its own module or its dependencies (uh.h only in Haptico);
- every file UhLibrary.Build.cs requires is present after staging (header, files.txt and what it
  lists), and the icon;
- every uh_* function the plugin resolves at run time (UhApi.h's list) is exported by the staged
  libuh (nm -D);
- the staged libuh is self-contained: RPATH $ORIGIN, and each library it loads outside the base
  system (glibc, libstdc++, libgcc_s) resolves inside the staged folder (ldd).

usage: check_plugin_files.py PLUGIN_DIR BUILD_DIR WORK_DIR
"""
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

BASE_SYSTEM = re.compile(r"^(linux-vdso|ld-linux|libc|libm|libdl|librt|libpthread|libstdc\+\+|libgcc_s)\.")
REQUIRED_UPLUGIN_FIELDS = ["FileVersion", "Version", "VersionName", "FriendlyName", "Description", "Category",
                           "EngineVersion", "SupportedTargetPlatforms", "Modules"]
MODULE_TYPES = {"Runtime", "Editor", "Developer", "UncookedOnly", "Program"}

failures = []


def fail(message):
    failures.append(message)
    print("FAIL:", message)


def stage(plugin_src, build_dir, work_dir):
    plugin = work_dir / "UnrealHaptics"
    shutil.rmtree(plugin, ignore_errors=True)
    shutil.copytree(plugin_src, plugin, ignore=shutil.ignore_patterns("Binaries", "Intermediate", "include", "lib", "data"))
    result = subprocess.run(["bash", str(plugin_src / "stage-libuh.sh"), str(build_dir), str(work_dir / "no-windows-build")],
                            env={"UH_PLUGIN_DIR": str(plugin), "PATH": "/usr/bin:/bin"}, capture_output=True, text=True)
    print(result.stdout.strip())
    if result.returncode != 0:
        fail(f"stage-libuh.sh failed: {result.stderr.strip()}")
    return plugin


def build_cs_modules(build_cs_text):
    """Module names a Build.cs lists as dependencies."""
    names = []
    for block in re.findall(r"DependencyModuleNames\.AddRange\(new string\[\]\s*\{([^}]*)\}", build_cs_text):
        names += re.findall(r'"([^"]+)"', block)
    return names


def check_uplugin(plugin):
    path = plugin / "UnrealHaptics.uplugin"
    try:
        descriptor = json.loads(path.read_text())
    except ValueError as error:
        fail(f"{path.name}: not valid JSON: {error}")
        return {}
    for field in REQUIRED_UPLUGIN_FIELDS:
        if field not in descriptor:
            fail(f"{path.name}: no field {field}")
    if descriptor.get("FileVersion") != 3:
        fail(f"{path.name}: FileVersion {descriptor.get('FileVersion')}, Unreal 5 reads 3")
    platforms = set(descriptor.get("SupportedTargetPlatforms", []))
    modules = {}
    for module in descriptor.get("Modules", []):
        name = module.get("Name", "")
        if module.get("Type") not in MODULE_TYPES:
            fail(f"{path.name}: module {name}: type {module.get('Type')}")
        if not name.startswith("UnrealHaptics"):
            fail(f"{path.name}: module {name}: module names are global to a project; prefix it UnrealHaptics")
        extra = set(module.get("PlatformAllowList", [])) - platforms
        if extra:
            fail(f"{path.name}: module {name} allows {sorted(extra)}, not in SupportedTargetPlatforms")
        modules[name] = module
    if not (plugin / "Resources" / "Icon128.png").is_file():
        fail("Resources/Icon128.png missing (the plugin browser's icon)")
    return modules


def check_modules(plugin, listed):
    source = plugin / "Source"
    on_disk = {p.name for p in source.iterdir() if p.is_dir() and p.name != "ThirdParty"}
    for name in sorted(on_disk - set(listed)):
        fail(f"Source/{name} is not a module of the .uplugin")
    for name in sorted(set(listed) - on_disk):
        fail(f".uplugin module {name} has no Source/{name}")
    third_party = {p.name for p in (source / "ThirdParty").iterdir() if p.is_dir()}
    known = set(listed) | third_party
    deps = {}
    for name in sorted(on_disk & set(listed)):
        folder = source / name
        build_cs = folder / f"{name}.Build.cs"
        if not build_cs.is_file():
            fail(f"Source/{name}: no {name}.Build.cs")
            continue
        text = build_cs.read_text()
        if not re.search(rf"public class {name}\s*:\s*ModuleRules", text) or f"public {name}(ReadOnlyTargetRules" not in text:
            fail(f"{build_cs.name}: does not declare class {name} with its constructor")
        deps[name] = build_cs_modules(text)
        for dep in deps[name]:
            if dep.startswith(("UnrealHaptics", "Uh")) and dep not in known:
                fail(f"{build_cs.name}: depends on {dep}, which the plugin does not have")
        sources = "\n".join(p.read_text() for p in folder.rglob("*.cpp"))
        if not re.search(rf"IMPLEMENT_MODULE\(\s*\w+\s*,\s*{name}\s*\)", sources):
            fail(f"Source/{name}: no IMPLEMENT_MODULE(..., {name})")
        for header in (folder / "Public").glob("*.h") if (folder / "Public").is_dir() else []:
            for macro in set(re.findall(r"\b(\w+)_API\b", header.read_text())):
                if macro not in ("UH", name.upper()):
                    fail(f"{name}/Public/{header.name}: {macro}_API, the module's macro is {name.upper()}_API")
    return deps


def reachable_dirs(plugin, module, deps):
    """Include folders a module's sources see: its own, and its dependencies' public ones."""
    source = plugin / "Source"
    dirs = [source / module / "Public", source / module / "Private"]
    for dep in deps.get(module, []):
        dirs.append(source / dep / "Public")
        dirs.append(source / "ThirdParty" / dep / "include")
    return dirs


def check_includes(plugin, deps):
    source = plugin / "Source"
    plugin_headers = {p.name for p in source.rglob("*.h")}
    for module in deps:
        dirs = reachable_dirs(plugin, module, deps)
        for file in sorted((source / module).rglob("*.[hc]*")):
            for include in re.findall(r'^#include "([^"]+)"', file.read_text(), re.M):
                if include.endswith(".generated.h") or Path(include).name not in plugin_headers:
                    continue  # an engine header
                if not any((d / include).is_file() for d in dirs):
                    fail(f"{file.relative_to(source)}: includes {include}, not reachable from module {module}")


def check_staged(plugin):
    module = plugin / "Source" / "ThirdParty" / "UhLibrary"
    build_cs = (module / "UhLibrary.Build.cs").read_text()
    # the files UhLibrary.Build.cs requires, by the path parts it names
    for parts in [("include", "uh", "uh.h"), ("lib", "Linux", "files.txt")]:
        if not all(f'"{p}"' in build_cs for p in parts):
            fail(f"UhLibrary.Build.cs no longer names {'/'.join(parts)}: update this check")
        if not module.joinpath(*parts).is_file():
            fail(f"after staging: {'/'.join(parts)} missing")
    lib = module / "lib" / "Linux"
    listed = [line.strip() for line in (lib / "files.txt").read_text().splitlines() if line.strip()] if (lib / "files.txt").is_file() else []
    for name in listed:
        if not (lib / name).is_file():
            fail(f"after staging: files.txt lists {name}, not staged")
    if "libuh.so" not in listed:
        fail("after staging: files.txt does not list libuh.so")
    if not (module / "data" / "bunny_npm_3674.obj").is_file():
        fail("after staging: data/bunny_npm_3674.obj (the demo's mesh) missing")
    demo = (plugin / "Source" / "UnrealHapticsDemo" / "Private" / "UnrealHapticsDemo.cpp").read_text()
    if "Source/ThirdParty/UhLibrary/data/bunny_npm_3674.obj" not in demo:
        fail("the demo reads its bunny from another path than the one stage-libuh.sh stages")
    return lib


def check_symbols(plugin, lib):
    api = (plugin / "Source" / "UnrealHapticsHaptico" / "Private" / "UhApi.h").read_text()
    names = re.findall(r"^\s*X\((uh_\w+)\)", api, re.M)
    if len(names) < 10:
        fail(f"UhApi.h: found {len(names)} functions in UH_API_FUNCTIONS: the list's form changed, update this check")
    nm = subprocess.run(["nm", "-D", "--defined-only", str(lib / "libuh.so")], capture_output=True, text=True)
    exported = {line.split()[-1] for line in nm.stdout.splitlines() if line.split()[1:2] == ["T"]}
    for name in names:
        if name not in exported:
            fail(f"the plugin resolves {name}; the staged libuh.so does not export it")
    print(f"{len(names)} functions the plugin resolves, all checked against {len(exported)} exported")


def check_self_contained(lib):
    dynamic = subprocess.run(["readelf", "-d", str(lib / "libuh.so")], capture_output=True, text=True).stdout
    if not re.search(r"\(RPATH\)\s+Library rpath: \[\$ORIGIN\]", dynamic):
        fail("staged libuh.so has no DT_RPATH [$ORIGIN]: its staged dependencies would not be found")
    ldd = subprocess.run(["ldd", str(lib / "libuh.so")], capture_output=True, text=True).stdout
    for line in ldd.splitlines():
        match = re.match(r"\s*(\S+) => (\S+)", line)
        if not match or BASE_SYSTEM.match(match.group(1)):
            continue
        name, path = match.groups()
        if Path(path).parent.resolve() != lib.resolve():
            fail(f"staged libuh.so loads {name} from {path}, not from the staged folder")


def main():
    plugin_src, build_dir, work_dir = (Path(a).resolve() for a in sys.argv[1:4])
    work_dir.mkdir(parents=True, exist_ok=True)
    plugin = stage(plugin_src, build_dir, work_dir)
    listed = check_uplugin(plugin)
    deps = check_modules(plugin, listed)
    check_includes(plugin, deps)
    lib = check_staged(plugin)
    if (lib / "libuh.so").is_file():
        check_symbols(plugin, lib)
        check_self_contained(lib)
    print(f"{len(failures)} failures" if failures else "the plugin's files are consistent")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
