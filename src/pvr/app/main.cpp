#include "pvr/app/cli.h"

int main(int argc, char** argv) { return pvr::runCli(argc, argv); }
