/*
 * analysis.h - what is computed from a model's state for output, never fed
 * back into a step: element stress, strain and principal stress fields
 * (element_fields.c), fragments, their sizes and the sieve curve
 * (fragments.c). The public functions are declared in fdem.h; this folder
 * reads the element and joint stages and nothing calls it.
 */
#ifndef FDEM_ANALYSIS_H
#define FDEM_ANALYSIS_H

#include "fdem.h"



#endif
