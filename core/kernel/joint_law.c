/*
 * joint_law.c - Munjiza's softening curve z(D) (Munjiza 2004 ch. 7, as in
 * Y-Geo: a = 0.63, b = 1.8, c = 6), the one out-of-line piece of the
 * cohesive law that joint_law.h shares between the 2D and 3D joints.
 */
#include <math.h>

#include "joint_law.h"

#define Z_A 0.63
#define Z_B 1.8
#define Z_C 6.0

double joint_softening(double D)
{
    if (D <= 0) return 1.0;
    if (D >= 1) return 0.0;
    double ab = Z_A + Z_B;
    double e = exp(D * (Z_A + Z_C * Z_B) / (ab * (1 - ab)));
    return (1 - (ab - 1) / ab * e) * (Z_A * (1 - D) + Z_B * pow(1 - D, Z_C));
}
