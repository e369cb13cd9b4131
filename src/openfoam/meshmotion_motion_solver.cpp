// The OpenFOAM half of the plugin (C++17, against Debian's OpenFOAM v1912): a
// displacementMotionSolver that constant/dynamicMeshDict selects as `motionSolver meshmotion;`.
// The boundary motion is 0/pointDisplacement's, so every point patch field drives it; the mover
// is set up once from points0 (again when the topology changes) and moves the interior at each
// solve(). Each patch's points are prescribed, slide or move with the interior as its point
// patch field says (patch_role()); a type the plugin does not know stops the run, naming it.

#include "bridge.hpp"

#include "addToRunTimeSelectionTable.H"
#include "displacementMotionSolver.H"
#include "globalIndex.H"
#include "globalMeshData.H"
#include "labelIOList.H"
#include "IStringStream.H"
#include "mapPolyMesh.H"
#include "memInfo.H"
#include "meshTools.H"
#include "OStringStream.H"
#include "Pstream.H"
#include "syncTools.H"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace Foam
{

class meshmotionMotionSolver
:
    public displacementMotionSolver
{
    std::unique_ptr<meshmotion::foam::Bridge> bridge_;
    std::vector<long> boundary_;
    std::vector<int> roles_;
    // Points on a patch of this rank that fixes their value: their value is this rank's to give
    // (a point of a decomposed case may be on a fixed patch only on another rank).
    std::vector<char> fixedHere_;
    // Some patch's points slide on a surface (surfaceSlipDisplacement): its field projects them
    // onto it after each move, as it does after displacementLaplacian's solve.
    bool projected_ = false;

    void setup();

public:

    TypeName("meshmotion");

    meshmotionMotionSolver(const polyMesh& mesh, const IOdictionary& dict)
    :
        displacementMotionSolver(mesh, dict, typeName)
    {
        setup();
    }

    tmp<pointField> curPoints() const override
    {
        tmp<pointField> points(points0() + pointDisplacement_.primitiveField());
        twoDCorrectPoints(points.ref());
        return points;
    }

    void solve() override;

    void updateMesh(const mapPolyMesh& map) override
    {
        displacementMotionSolver::updateMesh(map);
        setup();
    }
};

defineTypeNameAndDebug(meshmotionMotionSolver, 0);
addToRunTimeSelectionTable(motionSolver, meshmotionMotionSolver, dictionary);


namespace
{

// What the mover does with a patch's points.
enum class PatchRole
{
    prescribed,  // the field fixes their value (the fixedValue family)
    held,        // a plain fixedValue whose value is zero at setup: a wall, not the moving body
    sliding,     // in the plane of the patch's faces at each point (two planes: along their line)
    normal,      // fixedNormalSlip: in the plane normal to the field's n
    surface,     // surfaceSlipDisplacement: in the faces' plane, then projected by the field
    interior     // moved with the interior: zeroGradient (as displacementLaplacian moves them),
                 // and a 2D case's front and back (curPoints() keeps them 2D as OpenFOAM's own
                 // solvers do; as centres they made every point of the case one)
};

// The role of a patch's points from its point patch field `field` and its patch type; a type
// the plugin does not know stops the run (a boundary treated as interior in silence moved
// fixedNormalSlip sides out of their planes).
PatchRole patch_role(const pointPatchVectorField& field, const polyPatch& patch)
{
    const word& type = field.type();
    if (field.fixesValue()) return PatchRole::prescribed;
    if (patch.type() == "empty" || patch.type() == "wedge") return PatchRole::interior;
    for (const word& slip : {"slip", "symmetry", "symmetryPlane"})
    {
        if (type == slip || patch.type() == slip) return PatchRole::sliding;
    }
    if (type == "fixedNormalSlip") return PatchRole::normal;
    if (type == "surfaceSlipDisplacement") return PatchRole::surface;
    if (type == "zeroGradient") return PatchRole::interior;
    FatalErrorInFunction << "meshmotion: patch " << patch.name() << " has pointDisplacement type " << type
        << " (patch type " << patch.type() << "), which the plugin does not know: give a fixedValue type to "
        << "prescribe its points; slip, symmetry, symmetryPlane, fixedNormalSlip or surfaceSlipDisplacement to "
        << "slide them; zeroGradient to move them with the interior" << exit(FatalError);
    return PatchRole::interior;
}

// fixedNormalSlip's unit normal: its `n`, as the field writes it.
vector fixed_normal(const pointPatchVectorField& field)
{
    OStringStream written;
    field.write(written);
    IStringStream read(written.str());
    const dictionary entries(read);
    const vector n = entries.get<vector>("n");
    if (mag(n) == 0)
    {
        FatalErrorInFunction << "meshmotion: patch " << field.patch().name() << ": fixedNormalSlip's n is zero"
            << exit(FatalError);
    }
    return n / mag(n);
}

// The entries of dynamicMeshDict that are OpenFOAM's, not options, where there is no
// meshmotionCoeffs and the options are read from the top level (as OpenFOAM's own motion
// solvers read theirs).
bool openfoam_entry(const entry& e)
{
    for (const word& key : {"dynamicFvMesh", "motionSolverLibs", "motionSolver", "solver", "libs"})
    {
        if (e.keyword() == key) return true;
    }
    return e.isDict();  // other solvers' coefficients
}

// Every entry of `coeffs` (meshmotionCoeffs, or dynamicMeshDict itself when `top`) but `method`
// and, at the top, OpenFOAM's own, as the library's "key=value" text.
std::string option_text(const dictionary& coeffs, bool top)
{
    std::string text;
    for (const entry& e : coeffs)
    {
        if (e.keyword() == "method" || (top && openfoam_entry(e))) continue;
        if (!e.isStream())
        {
            FatalIOErrorInFunction(coeffs) << "meshmotion: option '" << e.keyword()
                << "' is a sub-dictionary; every option is a key and a value" << exit(FatalIOError);
        }
        OStringStream value;
        const ITstream& tokens = e.stream();
        forAll(tokens, t)
        {
            if (t) value << ' ';
            value << tokens[t];
        }
        text += e.keyword() + "=" + value.str() + " ";
    }
    return text;
}

// A figure for the log to `digits` significant digits: OpenFOAM's streams write every digit.
std::string significant(double value, int digits)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    return text;
}

std::string seconds_text(double seconds)
{
    return significant(seconds, 3) + " s";
}

double seconds_since(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace


void meshmotionMotionSolver::setup()
{
    const polyMesh& m = mesh();
    const dictionary& coeffs = coeffDict();
    meshmotion::foam::BridgeInput input;
    input.method = coeffs.lookupOrDefault<word>("method", "rbf");
    input.options = option_text(coeffs, !found(typeName + "Coeffs"));

    // Each boundary point: prescribed when a patch fixes its value, else sliding on the planes
    // of its sliding patches (two planes: along their common line). A plane's normal at a point
    // is the mean of its faces' normals there. On a decomposed case both are summed over the
    // ranks that hold the point, so every rank sees what the serial run sees.
    const label n = m.nPoints();
    labelList prescribed(n, 0), held(n, 0);
    fixedHere_.assign(n, 0);
    PtrList<vectorField> normalSums;
    projected_ = false;
    forAll(m.boundaryMesh(), patchi)
    {
        const pointPatchVectorField& field = pointDisplacement_.boundaryField()[patchi];
        const polyPatch& patch = m.boundaryMesh()[patchi];
        if (patch.coupled()) continue;  // processor and cyclic patches: not walls
        const labelList& points = patch.meshPoints();
        PatchRole role = patch_role(field, patch);
        // A wall held by a plain fixedValue of zero is not part of the moving body whose rigid
        // part the RBF fits at each move (over every rank: the patches are the same on all).
        // The RBF still takes its value at every step (a coupling that writes into it moves it);
        // the other methods read a fixed point as still, so for them it stays prescribed.
        const vectorField* given = dynamic_cast<const vectorField*>(&field);
        if (input.method == "rbf" && role == PatchRole::prescribed && field.type() == "fixedValue" && given &&
            gMax(mag(*given)) <= 0)
        {
            role = PatchRole::held;
        }
        if (role == PatchRole::prescribed || role == PatchRole::held)
        {
            labelList& into = role == PatchRole::held ? held : prescribed;
            forAll(points, i) into[points[i]] = fixedHere_[points[i]] = 1;
        }
        else if (role != PatchRole::interior)
        {
            // On every rank alike: the patches are the same, in the same order, on all of them.
            projected_ = projected_ || role == PatchRole::surface;
            normalSums.append(new vectorField(n, Zero));
            vectorField& sum = normalSums.last();
            const vectorField& faceNormals = patch.faceNormals();
            const vector given = role == PatchRole::normal ? fixed_normal(field) : vector::zero;
            forAll(patch, facei)
            {
                for (const label p : patch.localFaces()[facei])
                {
                    sum[points[p]] += role == PatchRole::normal ? given : faceNormals[facei];
                }
            }
        }
    }
    syncTools::syncPointList(m, prescribed, maxEqOp<label>(), label(0));
    syncTools::syncPointList(m, held, maxEqOp<label>(), label(0));
    forAll(normalSums, k)
    {
        syncTools::syncPointList(m, normalSums[k], plusEqOp<vector>(), vector::zero);
    }
    boundary_.clear();
    roles_.clear();
    for (label v = 0; v < n; ++v)
    {
        std::vector<vector> planes;
        const bool given = prescribed[v] || held[v];  // a point of a moving patch and a wall moves
        if (!given)
        {
            forAll(normalSums, k)
            {
                const vector& sum = normalSums[k][v];
                if (mag(sum) == 0) continue;
                const vector normal = sum / mag(sum);
                bool known = false;
                for (const vector& q : planes) known = known || mag(normal ^ q) < 1e-6;
                if (!known) planes.push_back(normal);
            }
            if (planes.empty()) continue;
        }
        vector along = Zero;
        int role = int(prescribed[v] || !held[v] ? meshmotion::foam::PointRole::prescribed : meshmotion::foam::PointRole::held);
        if (planes.size() == 1)
        {
            role = int(meshmotion::foam::PointRole::sliding_plane);
            along = planes[0];
        }
        else if (planes.size() == 2)
        {
            role = int(meshmotion::foam::PointRole::sliding_line);
            along = planes[0] ^ planes[1];
            along /= mag(along);
        }
        boundary_.push_back(v);
        roles_.push_back(role);
        for (direction d = 0; d < 3; ++d) input.directions.push_back(along[d]);
    }
    input.boundary = boundary_;
    input.roles = roles_;
    const pointField& p0 = points0();
    input.points.resize(3 * p0.size());
    forAll(p0, i)
    {
        for (direction d = 0; d < 3; ++d) input.points[3 * i + d] = p0[i][d];
    }
    if (meshmotion::foam::needs_cells(input.method))
    {
        const faceList& faces = m.faces();
        input.face_offsets.reserve(faces.size() + 1);
        input.face_offsets.push_back(0);
        for (const face& f : faces)
        {
            input.face_points.insert(input.face_points.end(), f.begin(), f.end());
            input.face_offsets.push_back(long(input.face_points.size()));
        }
        input.owner.assign(m.faceOwner().begin(), m.faceOwner().end());
        input.neighbour.assign(m.faceNeighbour().begin(), m.faceNeighbour().end());
        input.cells = m.nCells();
        forAll(m.boundaryMesh(), patchi)
        {
            const polyPatch& patch = m.boundaryMesh()[patchi];
            if (!patch.coupled()) continue;
            for (label f = patch.start(); f < patch.start() + patch.size(); ++f) input.coupled_faces.push_back(f);
        }
    }
    if (Pstream::parRun())
    {
        // One number per point of the whole case (a point shared by ranks has one), and its
        // owner: the rank whose range of that numbering holds it.
        labelList pointToGlobal, uniquePoints;
        const autoPtr<globalIndex> numbering = m.globalData().mergePoints(pointToGlobal, uniquePoints);
        input.global_ids.assign(pointToGlobal.begin(), pointToGlobal.end());
        input.owners.resize(n);
        forAll(pointToGlobal, i) input.owners[i] = numbering().whichProcID(pointToGlobal[i]);
        // The serial case's numbering where decomposePar left it (pointProcAddressing) replaces
        // mergePoints', which follows the ranks: the distributed mover then samples its memory
        // estimate and orders its centres as the serial run does, so a default radius cut to
        // that estimate is the serial one.
        IOobject addressing("pointProcAddressing", m.facesInstance(), polyMesh::meshSubDir, m, IOobject::MUST_READ,
                            IOobject::NO_WRITE, false);
        labelList serial;
        if (addressing.typeHeaderOk<labelIOList>(true)) serial = labelIOList(addressing);
        if (returnReduce(serial.size() == n, andOp<bool>())) input.global_ids.assign(serial.begin(), serial.end());
    }
    bridge_.reset();
    const auto start = std::chrono::steady_clock::now();
    try
    {
        bridge_ = std::make_unique<meshmotion::foam::Bridge>(input);
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction << e.what() << exit(FatalError);
    }
    Info<< "meshmotion: " << input.method.c_str() << " set up on "
        << returnReduce(label(boundary_.size()), sumOp<label>()) << " boundary points of "
        << returnReduce(n, sumOp<label>());
    if (Pstream::parRun()) Info<< " on " << Pstream::nProcs() << " ranks (points on several ranks counted on each)";
    if (bridge_->support_radius() > 0) Info<< " (support radius " << significant(bridge_->support_radius(), 6).c_str() << ")";
    if (bridge_->rigid_part()) Info<< ", each move's rigid part blended first";
    // The setup's cost, as each step's line gives the move's.
    Info<< " in " << seconds_text(seconds_since(start)).c_str() << ", resident memory " << memInfo().update().rss() / 1024 << " MB" << endl;
}


void meshmotionMotionSolver::solve()
{
    movePoints(mesh().points());
    // The patches' values on their points: OpenFOAM's own rule for a point of several patches.
    pointDisplacement_.boundaryFieldRef().updateCoeffs();
    pointDisplacement_.correctBoundaryConditions();
    // On a decomposed case, a point's value comes from a rank with a fixed patch there (the
    // largest, as OpenFOAM syncs point values, where ranks' patches disagree).
    vectorField values(pointDisplacement_.primitiveField());
    forAll(values, i)
    {
        if (!fixedHere_[i]) values[i] = Zero;
    }
    syncTools::syncPointList(mesh(), values, maxMagSqrEqOp<vector>(), vector::zero);
    std::vector<double> d(3 * boundary_.size(), 0.0);
    for (std::size_t k = 0; k < boundary_.size(); ++k)
    {
        if (roles_[k] != int(meshmotion::foam::PointRole::prescribed) && roles_[k] != int(meshmotion::foam::PointRole::held)) continue;
        for (direction c = 0; c < 3; ++c) d[3 * k + c] = values[boundary_[k]][c];
    }
    std::vector<double> out;
    const int setups = bridge_->setups();
    const auto start = std::chrono::steady_clock::now();
    try
    {
        bridge_->move(d, out);
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction << e.what() << exit(FatalError);
    }
    const double seconds = seconds_since(start);
    if (bridge_->setups() > setups)
    {
        Info<< "meshmotion: set up again for the motion's size (support radius "
            << significant(bridge_->support_radius(), 6).c_str() << ")"
            << endl;
    }
    // Where the time goes, as OpenFOAM's solvers log their residuals: this rank's. What is
    // neither set up again nor solved is evaluation (and the plugin's own copying).
    const double rebuild = bridge_->rebuild_seconds(), solve = bridge_->solve_seconds();
    Info<< "meshmotion: moved in " << seconds_text(seconds).c_str() << " (set up again " << seconds_text(rebuild).c_str()
        << ", solve " << seconds_text(solve).c_str() << ", evaluation "
        << seconds_text(std::max(0.0, seconds - rebuild - solve)).c_str() << "), ";
    if (bridge_->solver_iterations() > 0) Info<< bridge_->solver_iterations() << " solver iterations, ";
    Info<< "resident memory " << memInfo().update().rss() / 1024 << " MB" << endl;
    vectorField& displacement = pointDisplacement_.primitiveFieldRef();
    forAll(displacement, i)
    {
        displacement[i] = vector(out[3 * i], out[3 * i + 1], out[3 * i + 2]);
    }
    if (projected_) pointDisplacement_.correctBoundaryConditions();
    // A 2D case moves in its plane: the movers through cells see a slab one cell thick, whose
    // front and back would follow the elasticity's Poisson effect out of it.
    meshTools::constrainDirection(mesh(), mesh().solutionD(), displacement);
}

}  // namespace Foam
