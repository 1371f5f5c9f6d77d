/*---------------------------------------------------------------------------*\
    grit: GritOkaErosion, see GritOkaErosion.H
\*---------------------------------------------------------------------------*/

#include "GritOkaErosion.H"

template<class CloudType>
Foam::label Foam::GritOkaErosion<CloudType>::applyToPatch
(
    const label globalPatchi
) const
{
    forAll(patchIDs_, i)
    {
        if (patchIDs_[i] == globalPatchi)
        {
            return i;
        }
    }
    return -1;
}


template<class CloudType>
void Foam::GritOkaErosion<CloudType>::write()
{
    if (massPtr_.valid())
    {
        massPtr_->write();
    }
}


template<class CloudType>
Foam::GritOkaErosion<CloudType>::GritOkaErosion
(
    const dictionary& dict,
    CloudType& owner,
    const word& modelName
)
:
    CloudFunctionObject<CloudType>(dict, owner, modelName, typeName),
    massPtr_(nullptr),
    patchIDs_(),
    coeffs_()
{
    const dictionary& d = this->coeffDict();
    patchIDs_ =
        owner.mesh().boundaryMesh().patchSet
        (
            d.template get<wordRes>("patches")
        ).sortedToc();
    coeffs_.E90 = d.template get<scalar>("E90");
    coeffs_.Hv = d.template get<scalar>("Hv");
    coeffs_.n1 = d.template get<scalar>("n1");
    coeffs_.n2 = d.template get<scalar>("n2");
    coeffs_.k2 = d.template get<scalar>("k2");
    coeffs_.k3 = d.template get<scalar>("k3");
    coeffs_.vRef = d.template get<scalar>("vRef");
    coeffs_.dRef = d.template get<scalar>("dRef");
}


template<class CloudType>
Foam::GritOkaErosion<CloudType>::GritOkaErosion
(
    const GritOkaErosion<CloudType>& ge
)
:
    CloudFunctionObject<CloudType>(ge),
    massPtr_(nullptr),
    patchIDs_(ge.patchIDs_),
    coeffs_(ge.coeffs_)
{}


template<class CloudType>
void Foam::GritOkaErosion<CloudType>::preEvolve()
{
    if (!massPtr_.valid())
    {
        const fvMesh& mesh = this->owner().mesh();
        massPtr_.reset
        (
            new volScalarField
            (
                IOobject
                (
                    this->owner().name() + ":gritErosionMass",
                    mesh.time().timeName(),
                    mesh,
                    IOobject::READ_IF_PRESENT,
                    IOobject::NO_WRITE
                ),
                mesh,
                dimensionedScalar("zero", dimMass, 0.0)
            )
        );
    }
}


template<class CloudType>
void Foam::GritOkaErosion<CloudType>::postPatch
(
    const parcelType& p,
    const polyPatch& pp,
    bool&
)
{
    const label patchi = pp.index();
    if (applyToPatch(patchi) == -1)
    {
        return;
    }

    vector nw;
    vector Up;
    this->owner().patchData(p, pp, nw, Up);

    // nw points out of the domain: a particle moving away from the wall erodes nothing
    const vector U = p.U() - Up;
    const scalar magU = mag(U);
    if ((nw & U) <= 0 || magU <= 0)
    {
        return;
    }

    // Impact angle from the wall, degrees, as grit's fit takes it
    const scalar cosToNormal = min(scalar(1), (nw & U)/magU);
    const scalar alphaDeg = 90.0 - radToDeg(acos(cosToNormal));

    const scalar E = grit::okaErosion(coeffs_, alphaDeg, magU, p.d());
    const label facei = pp.whichFace(p.face());
    massPtr_->boundaryFieldRef()[patchi][facei] += p.nParticle()*p.mass()*E;
}
