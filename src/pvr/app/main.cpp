#include <cstdio>

#include "pvr/app/cli.h"
#include "pvr/util/fault_injection.h"

int main(int argc, char** argv) {
  const int rc = pvr::runCli(argc, argv);
  // Under PVR_INJECT_FAULT a run that ends well says whether the planned fault happened: the
  // tests' sweeps tell the end of the events from a fault that was swallowed.
  if (rc == 0) {
    try {
      const std::string report = pvr::faultPlanReport();
      if (!report.empty()) std::fprintf(stderr, "photonvr: %s\n", report.c_str());
    } catch (const std::exception&) {  // a malformed plan was refused by runCli already
    }
  }
  return rc;
}
