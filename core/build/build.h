/*
 * build.h - the model's life cycle above the stages: building it from
 * materials, parts and constraints (build.c), finalizing it into one that
 * steps by preparing each stage in order (finalize.c), and pricing its
 * memory before and after (memory.c). The public functions are declared
 * in fdem.h; this folder calls every stage and no stage calls it.
 */
#ifndef FDEM_BUILD_H
#define FDEM_BUILD_H

#include "fdem.h"



#endif
