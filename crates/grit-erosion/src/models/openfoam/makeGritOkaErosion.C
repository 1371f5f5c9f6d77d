/*---------------------------------------------------------------------------*\
    grit: registers GritOkaErosion for basicKinematicCollidingCloud, the cloud of
    DPMFoam and icoUncoupledKinematicParcelFoam. Another cloud type needs a file
    of its own with the same line (the macro typedefs kinematicCloudType).
\*---------------------------------------------------------------------------*/

#include "basicKinematicCollidingCloud.H"
#include "makeParcelCloudFunctionObjects.H"
#include "GritOkaErosion.H"

makeCloudFunctionObjectType(GritOkaErosion, basicKinematicCollidingCloud);
