// Console tests of UnrealHaptics.dll under Mono against the real libuh (scripts/test.sh runs them
// after the Release build; LD_LIBRARY_PATH points at libuh). Each test is a method named Test*;
// the run ends with "N passed, N failed" and exit code 1 on any failure.

using System;
using System.Collections.Generic;
using System.Globalization;
using System.IO;
using System.Reflection;
using System.Runtime.InteropServices;
using System.Text.RegularExpressions;
using System.Threading;
using UnrealHaptics;

static class SessionTests
{
    static int Main()
    {
        int passed = 0, failed = 0;
        foreach (var m in typeof(SessionTests).GetMethods(BindingFlags.Static | BindingFlags.NonPublic))
        {
            if (!m.Name.StartsWith("Test")) continue;
            try
            {
                m.Invoke(null, null);
                ++passed;
                Console.WriteLine("ok: " + m.Name);
            }
            catch (TargetInvocationException e)
            {
                ++failed;
                Console.WriteLine("FAILED: " + m.Name + ": " + e.InnerException.Message);
            }
        }
        Console.WriteLine(passed + " passed, " + failed + " failed");
        return failed == 0 ? 0 : 1;
    }

    static void Expect(bool ok, string what)
    {
        if (!ok) throw new Exception(what);
    }

    static double Norm(double[] v)
    {
        double s = 0;
        foreach (var x in v) s += x * x;
        return Math.Sqrt(s);
    }

    // the first number named `key` after the report's "section": key (the report is nlohmann JSON,
    // sorted keys; the tests read keys that are unique within their section)
    static double ReportNumber(string json, string section, string key)
    {
        var start = json.IndexOf("\"" + section + "\":");
        Expect(start >= 0, "the report has a section " + section);
        var m = new Regex("\"" + key + "\":\\s*(-?[0-9.eE+-]+)").Match(json, start);
        Expect(m.Success, "the report has " + section + "." + key);
        return double.Parse(m.Groups[1].Value, CultureInfo.InvariantCulture);
    }

    static void TestTheLibraryAndTheBindingSpeakTheSameApi()
    {
        Expect(Native.uh_api_version() == Native.ApiVersion, "UH_API_VERSION " + Native.uh_api_version());
        var version = Native.Utf8Out(Native.uh_version_string());
        Expect(Regex.IsMatch(version, "^[0-9]+\\.[0-9]+\\.[0-9]+"), "a version string: " + version);
        Expect(Marshal.SizeOf(typeof(Native.uh_state)) == 168,
               "uh_state as in C (168 bytes): " + Marshal.SizeOf(typeof(Native.uh_state)));
        Expect(Marshal.SizeOf(typeof(Native.uh_contact_event)) == 40, "uh_contact_event as in C (40 bytes)");
        Expect(Marshal.SizeOf(typeof(Native.uh_session_id)) == 8, "ids are 64-bit values");
        var defaults = Native.DefaultToolDef();
        Expect(defaults.workspace_scale == 1.0 && defaults.workspace_rotation_w == 1.0 && defaults.tool_offset_z == 0.0,
               "the library's tool defaults fill this binding's layout");
    }

    // A second tool on its own device, far from the bunny: every contact event names the first.
    static void TestASecondToolIsAddedAndEventsNameTheirTool()
    {
        var source = Environment.GetEnvironmentVariable("UH_SOURCE_DIR");
        Expect(!string.IsNullOrEmpty(source), "UH_SOURCE_DIR names the repository (scripts/test.sh sets it)");
        using (var scene = Scene.Load())
        {
            var index = scene.AddTool(new ToolSettings
            {
                Name = "far", MeshPath = Path.Combine(source, "assets/meshes/stylus.obj"), MetersPerUnit = 0.01,
                Spheres = 150, DeviceDriver = "sim-line",
                DeviceConfigJson = "{\"start\": [1, 0, 0.1], \"end\": [1, 0, 0.2]}",
            });
            Expect(index == 1 && scene.ToolCount == 2, "the second tool's index: " + index);
            using (var s = Session.Create(scene, Environment.GetEnvironmentVariable("UH_CACHE_DIR")))
            {
                s.RunStepped(3.0, 4);
                ContactEvent e;
                int begins = 0;
                while (s.PollEvent(out e))
                {
                    Expect(e.Tool == 0, "only the first tool touches: " + e.Tool);
                    if (e.Kind == ContactKind.Begin) ++begins;
                }
                Expect(begins >= 1, "the first tool touched the bunny");
            }
        }
    }

    static void TestTheDefaultSessionRunsPollsAndStopsWithTheReportAndZeroForce()
    {
        using (var s = Session.Open())
        {
            Expect(s.ObjectCount == 1 && s.ObjectName(0) == "bunny", "the default scene holds the bunny");
            s.Start();
            State st = s.Poll();
            var until = DateTime.UtcNow.AddSeconds(60);
            while (st.HapticTicks < 200 && DateTime.UtcNow < until)
            {
                Thread.Sleep(20);
                st = s.Poll();
            }
            Expect(st.HapticTicks >= 200, "the haptic thread ticks: " + st.HapticTicks);
            Expect(!s.EndedByItself, "a session that runs as it should has not ended by itself");
            Expect(Math.Abs(Norm(st.ToolOrientation) - 1.0) < 1e-9, "a unit orientation");
            foreach (var f in st.Force) Expect(!double.IsNaN(f) && !double.IsInfinity(f), "a finite force");
            var report = s.Stop();
            Expect(ReportNumber(report, "haptic", "ticks") >= 200, "the report counts the ticks");
            var after = s.Poll();
            Expect(Norm(after.Force) == 0.0 && Norm(after.Torque) == 0.0, "zero force after Stop()");
            Expect(s.Stop() == report, "Stop() is idempotent");
            Expect(!s.EndedByItself, "stopped, not ended by itself");
        }
    }

    static void TestASteppedRunCallsBackOnEveryTickAndReportsContacts()
    {
        using (var s = Session.Open())
        {
            s.CountTicks();
            s.RunStepped(3.0, 4);
            var st = s.Poll();
            Expect(st.HapticTicks == 3000, "3000 ticks in 3 s at 1 kHz: " + st.HapticTicks);
            // every tick, and the zero sent one period after the last
            Expect(s.TickCallbacks == 3001, "the tick callback ran once per tick: " + s.TickCallbacks);
            var begins = 0;
            ContactEvent e;
            while (s.PollEvent(out e))
            {
                if (e.Kind != ContactKind.Begin) continue;
                ++begins;
                // through the proxy, the default, which rests on the surface: its rows in contact, no overlap
                Expect(e.Object == 0 && e.Volume == 0 && e.Pairs > 0, "a begin names the bunny with its contact rows");
            }
            Expect(begins > 0, "the sweep touches the bunny");
            var report = s.Stop();
            Expect(ReportNumber(report, "force", "max_n") > 0.0, "the report has the force");
        }
    }

    static void TestDisposeAlwaysStopsAndAClosedSessionIsRefused()
    {
        var s = Session.Open();
        s.Start();
        s.Dispose();  // without Stop(): stops and joins
        s.Dispose();  // twice is fine
        var refused = false;
        try { s.Poll(); } catch (ObjectDisposedException) { refused = true; }
        Expect(refused, "a disposed session refuses calls");
        using (var idle = Session.Open()) { }  // never started
    }

    static void TestErrorsNameWhatIsWrong()
    {
        try
        {
            Session.Open("/nonexistent/scene.json");
            Expect(false, "a missing scene file is an error");
        }
        catch (UhException e)
        {
            Expect(e.Status == Native.UH_ERROR_FILE, "UH_ERROR_FILE: " + e.Status);
            Expect(e.Message.Contains("/nonexistent/scene.json"), "names the file: " + e.Message);
        }
        using (var s = Session.Open())
        {
            s.Start();
            try
            {
                s.Start();
                Expect(false, "starting twice is an error");
            }
            catch (UhException e)
            {
                Expect(e.Status == Native.UH_ERROR_WRONG_STATE, "UH_ERROR_WRONG_STATE: " + e.Message);
            }
        }
    }

    static void TestSeveralSessionsRunAtOnce()
    {
        using (var a = Session.Open())
        using (var b = Session.Open())
        {
            a.Start();
            b.Start();
            var until = DateTime.UtcNow.AddSeconds(60);
            while ((a.Poll().HapticTicks < 50 || b.Poll().HapticTicks < 50) && DateTime.UtcNow < until) Thread.Sleep(20);
            Expect(a.Poll().HapticTicks >= 50 && b.Poll().HapticTicks >= 50, "both sessions tick");
        }
    }

    // A closed mesh from arrays (an engine's own mesh): a box, added to the default scene.
    static void TestAMeshFromArraysBecomesAnObject()
    {
        double[] v = { -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1 };
        int[] t = { 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7 };
        using (var scene = Scene.Load())
        {
            var index = scene.AddMesh("box", v, t, new double[] { 0.3, 0, 0 }, null, 200, 0.01);
            Expect(index == 1 && scene.ObjectCount == 2, "the box is object 1");
            var bad = (int[])t.Clone();
            bad[5] = 99;
            try
            {
                scene.AddMesh("broken", v, bad, null, null, 200, 0.01);
                Expect(false, "an index out of range is an error");
            }
            catch (UhException e)
            {
                Expect(e.Message.Length > 0 && scene.ObjectCount == 2, "refused, nothing added: " + e.Message);
            }
            using (var s = Session.Create(scene, Environment.GetEnvironmentVariable("UH_CACHE_DIR")))
            {
                Expect(s.ObjectCount == 2 && s.ObjectName(1) == "box", "the session has the box");
                s.RunStepped(0.2, 4);
            }
        }
    }

    // The tool set through the API (the ForceComponent's settings): its force law reaches the report.
    static void TestAToolWithItsForceLawIsSetThroughTheApi()
    {
        var source = Environment.GetEnvironmentVariable("UH_SOURCE_DIR");
        Expect(!string.IsNullOrEmpty(source), "UH_SOURCE_DIR names the repository (scripts/test.sh sets it)");
        using (var scene = Scene.Load())
        {
            scene.SetTool(new ToolSettings
            {
                Name = "probe", MeshPath = Path.Combine(source, "assets/meshes/stylus.obj"), MetersPerUnit = 0.01,
                Spheres = 300, MaxForceN = 2.5, DeviceDriver = "sim-raster",
                // the default scene's sweep, which comes out of the bunny's flank and back in: the
                // driver's default box lies inside the bunny, where the proxy leaves the tool free
                DeviceConfigJson = "{\"min\": [-0.04, -0.025, 0.0], \"max\": [0.04, 0.025, 0.0965], \"depth\": 0.045}",
            });
            var refused = false;
            try { scene.SetTool(new ToolSettings { MeshPath = "/nonexistent/tool.obj" }); }
            catch (UhException e) { refused = e.Message.Contains("/nonexistent/tool.obj"); }
            Expect(refused, "a missing tool mesh is an error naming it");
            using (var s = Session.Create(scene, Environment.GetEnvironmentVariable("UH_CACHE_DIR")))
            {
                s.RunStepped(3.0, 4);
                var report = s.Stop();
                var max = ReportNumber(report, "force", "max_n");
                Expect(max > 0.0 && max <= 2.5 + 1e-9, "the tool's force limit of 2.5 N holds: " + max);
            }
        }
    }
}
