#pragma once
/// The dimensions of the bundled wing-section example (in the spirit of Figure 1 of the
/// α-SIM paper): one place for every number, shared by the part builders, the harness
/// and the scene writer so that ports sit exactly on the receptacles.
///
/// World frame, millimetres: X along the span (0 … 1500, root → tip), Y along the chord
/// (front spar at small Y, rear spar at large Y), Z through the depth (0 … 200).

namespace loom::examples::layout {

// --- envelope -------------------------------------------------------------------------
constexpr double kSpan = 1500.0;   ///< mm, length of the spars along X
constexpr double kChord = 800.0;   ///< mm, chord reference (spars mirror about kChord/2)
constexpr double kDepth = 200.0;   ///< mm, spar height along Z

// --- spars (C-section; the front one is modelled, the rear one is its 180° turn) ---------
constexpr double kSparWebY0 = 80.0;     ///< mm, front face of the front spar web
constexpr double kSparWebT = 6.0;       ///< mm, web thickness (Y)
constexpr double kSparFlangeW = 40.0;   ///< mm, flange width (Y), pointing aft
constexpr double kSparFlangeT = 5.0;    ///< mm, flange thickness (Z)
constexpr double kSparRivetPitch = 30.0;  ///< mm, rivet spacing along the flanges
/// mm, Y of the inner face of the front spar web (= start of the rib web)
constexpr double kSparInnerY = kSparWebY0 + kSparWebT;
/// mm, Y of the inner face of the rear spar web (the rear spar is the front one turned)
constexpr double kRearSparInnerY = kChord - kSparInnerY;

// --- ribs (plates normal to X with caps; modelled at x = 0, placed by translation) ------
constexpr int kRibCount = 5;  ///< number of ribs
constexpr double kRibX[kRibCount] = {150.0, 450.0, 750.0, 1050.0, 1350.0};  ///< mm, mid-planes
constexpr double kRibT = 3.0;           ///< mm, web thickness (X)
constexpr double kRibCapW = 30.0;       ///< mm, cap width (X)
constexpr double kRibCapT = 3.0;        ///< mm, cap thickness (Z)
constexpr double kRibRivetPitch = 40.0;  ///< mm, rivet spacing along the caps
constexpr int kLighteningCount = 3;  ///< lightening holes per rib
constexpr double kLighteningY[kLighteningCount] = {230.0, 400.0, 570.0};  ///< mm, hole centres
constexpr double kLighteningZ = 100.0;  ///< mm, hole centre height
constexpr double kLighteningR = 55.0;   ///< mm, radius of the lightening holes (kept by α-SIM)
constexpr double kRivetR = 2.0;         ///< mm, rivet hole radius (Ø4: suppressed by α-SIM)

// --- harness trunk: along the span behind the front spar, through the lightening holes -
constexpr double kTrunkY = kLighteningY[0];  ///< mm
constexpr double kTrunkZ = kLighteningZ;     ///< mm

// --- receptacles (cylindrical connector shells) ------------------------------------------
/// The shape of one receptacle: a shell standing on a face, bored from its mouth.
struct ReceptacleSpec {
  double r_out;       ///< mm, outer radius of the shell
  double r_in;        ///< mm, bore radius
  double length;      ///< mm, shell height above the face it stands on
  double bore_depth;  ///< mm, depth of the bore from the mouth (the insert sits below)
  double port_gap;    ///< mm, distance from the mouth to the harness port along the axis
};
constexpr ReceptacleSpec kBoxReceptacle{14.0, 11.0, 25.0, 12.0, 12.0};   ///< avionics boxes
/// The actuator's receptacle: as the boxes', with its port further out because the
/// actuator asks for extra clearance.
constexpr ReceptacleSpec kActReceptacle{14.0, 11.0, 25.0, 12.0, 20.0};
constexpr ReceptacleSpec kTrunkReceptacle{20.0, 16.0, 25.0, 12.0, 14.0};  ///< root and tip

// --- avionics boxes (modelled centred on x = 0, placed by translation) --------------------
constexpr int kBoxCount = 3;  ///< avionics boxes
constexpr double kBoxX[kBoxCount] = {300.0, 900.0, 1200.0};  ///< mm, box centres (bays 1, 3, 4)
constexpr double kBoxHalfW = 90.0;   ///< mm, half width along X
constexpr double kBoxY0 = 400.0;     ///< mm, front face (receptacles face −Y, towards the trunk)
constexpr double kBoxY1 = 560.0;     ///< mm, rear face
constexpr double kBoxZ0 = 40.0;      ///< mm
constexpr double kBoxZ1 = 160.0;     ///< mm
constexpr double kBoxReceptacleDX = 50.0;  ///< mm, receptacles at x = ±50 about the centre
constexpr double kBoxReceptacleZ = 100.0;  ///< mm

// --- actuator (bay 2, world frame) ---------------------------------------------------------
constexpr double kActAxisY = 600.0;   ///< mm, cylinder axis (parallel to X)
constexpr double kActAxisZ = 100.0;   ///< mm
constexpr double kActBodyR = 35.0;    ///< mm
constexpr double kActBodyX0 = 480.0;  ///< mm
constexpr double kActBodyX1 = 650.0;  ///< mm
constexpr double kActRodR = 10.0;     ///< mm
constexpr double kActRodX1 = 718.0;   ///< mm, end of the rod
constexpr double kActEyeR = 12.0;     ///< mm, rod-end eye (sphere)
constexpr double kActReceptacleX = 520.0;  ///< mm, receptacle on the −Y side of the body
/// mm, the swept envelope of the rod and rod end (keep-out zone), as a box
constexpr double kActEnvelope[6] = {650.0, 575.0, 75.0, 745.0, 625.0, 125.0};

// --- root / tip connector brackets (root modelled, tip = root turned 180° about Y) -------
constexpr double kConnPlateX0 = 40.0;  ///< mm, bracket plate (6 mm thick, on the front spar)
constexpr double kConnPlateT = 6.0;    ///< mm
constexpr double kConnPlateY1 = 300.0;  ///< mm, plate extends from the spar web to here
constexpr double kConnPlateZ0 = 60.0;  ///< mm
constexpr double kConnPlateZ1 = 140.0;  ///< mm

}  // namespace loom::examples::layout
