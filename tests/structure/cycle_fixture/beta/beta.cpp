#include "plslam/beta/beta.h"

#include "plslam/alpha/alpha.h"
