#include "apps/cli.h"

int main(int argc, char** argv) { return gins::RunCli(argc, argv, /*own_process=*/true); }
