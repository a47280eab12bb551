#pragma once
// The photonvr command line. Returns the process exit code: 0 on success, 1 for bad input or a
// failed render (one line on stderr), 2 for bad usage (one line on stderr).
namespace pvr {
int runCli(int argc, char** argv);
}
