#pragma once
// The photonvr command line. Returns the process exit code: 0 on success, 1 for bad input or a
// failed render (one line on stderr), 2 for bad usage (one line on stderr).
namespace pvr {

// What runCli does once the command line is parsed: run the command, or (the command-line fuzz
// harness, tests/fuzz/fuzz_cli.cpp) only check it: the render options converted and validated
// for a default rig, settings files read, nothing else loaded, rendered or written.
enum class CliRun { Execute, CheckOnly };

int runCli(int argc, char** argv, CliRun run = CliRun::Execute);

}  // namespace pvr
