// Sub-commands of bims-eval (each parses its own arguments).
#pragma once

int cmdTraj(int argc, char** argv);
int cmdMasks(int argc, char** argv);
int cmdDepthConsistency(int argc, char** argv);
int cmdAttitude(int argc, char** argv);
