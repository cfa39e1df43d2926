// NREL SPA, written from the paper (Reda & Andreas 2004/2008), not from NREL's spa.c (whose
// licence forbids redistribution). Steps are numbered as in the paper's section 3.
#include "core/sun/sun_position_spa.h"
#include "core/geometry/math_constants.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <string_view>

namespace arpipe {

namespace {

constexpr double kDeg = kPi / 180.0;

double rad(double deg) { return deg * kDeg; }
double deg(double r) { return r / kDeg; }
double limit_degrees(double d) {  // into [0, 360)
  d = std::fmod(d, 360.0);
  return d < 0 ? d + 360.0 : d;
}

struct Term {
  double a, b, c;  // A cos(B + C·JME)
};

// Table A4.2: Earth periodic terms (VSOP87 abridged, as in Meeus' Astronomical Algorithms).
constexpr Term kL0[] = {
    {175347046, 0, 0},           {3341656, 4.6692568, 6283.07585}, {34894, 4.6261, 12566.1517},
    {3497, 2.7441, 5753.3849},   {3418, 2.8289, 3.5231},           {3136, 3.6277, 77713.7715},
    {2676, 4.4181, 7860.4194},   {2343, 6.1352, 3930.2097},        {1324, 0.7425, 11506.7698},
    {1273, 2.0371, 529.691},     {1199, 1.1096, 1577.3435},        {990, 5.233, 5884.927},
    {902, 2.045, 26.298},        {857, 3.508, 398.149},            {780, 1.179, 5223.694},
    {753, 2.533, 5507.553},      {505, 4.583, 18849.228},          {492, 4.205, 775.523},
    {357, 2.92, 0.067},          {317, 5.849, 11790.629},          {284, 1.899, 796.298},
    {271, 0.315, 10977.079},     {243, 0.345, 5486.778},           {206, 4.806, 2544.314},
    {205, 1.869, 5573.143},      {202, 2.458, 6069.777},           {156, 0.833, 213.299},
    {132, 3.411, 2942.463},      {126, 1.083, 20.775},             {115, 0.645, 0.98},
    {103, 0.636, 4694.003},      {102, 0.976, 15720.839},          {102, 4.267, 7.114},
    {99, 6.21, 2146.17},         {98, 0.68, 155.42},               {86, 5.98, 161000.69},
    {85, 1.3, 6275.96},          {85, 3.67, 71430.7},              {80, 1.81, 17260.15},
    {79, 3.04, 12036.46},        {75, 1.76, 5088.63},              {74, 3.5, 3154.69},
    {74, 4.68, 801.82},          {70, 0.83, 9437.76},              {62, 3.98, 8827.39},
    {61, 1.82, 7084.9},          {57, 2.78, 6286.6},               {56, 4.39, 14143.5},
    {56, 3.47, 6279.55},         {52, 0.19, 12139.55},             {52, 1.33, 1748.02},
    {51, 0.28, 5856.48},         {49, 0.49, 1194.45},              {41, 5.37, 8429.24},
    {41, 2.4, 19651.05},         {39, 6.17, 10447.39},             {37, 6.04, 10213.29},
    {37, 2.57, 1059.38},         {36, 1.71, 2352.87},              {36, 1.78, 6812.77},
    {33, 0.59, 17789.85},        {30, 0.44, 83996.85},             {30, 2.74, 1349.87},
    {25, 3.16, 4690.48}};
constexpr Term kL1[] = {
    {628331966747, 0, 0}, {206059, 2.678235, 6283.07585}, {4303, 2.6351, 12566.1517}, {425, 1.59, 3.523},
    {119, 5.796, 26.298}, {109, 2.966, 1577.344},         {93, 2.59, 18849.23},        {72, 1.14, 529.69},
    {68, 1.87, 398.15},   {67, 4.41, 5507.55},            {59, 2.89, 5223.69},         {56, 2.17, 155.42},
    {45, 0.4, 796.3},     {36, 0.47, 775.52},             {29, 2.65, 7.11},            {21, 5.34, 0.98},
    {19, 1.85, 5486.78},  {19, 4.97, 213.3},              {17, 2.99, 6275.96},         {16, 0.03, 2544.31},
    {16, 1.43, 2146.17},  {15, 1.21, 10977.08},           {12, 2.83, 1748.02},         {12, 3.26, 5088.63},
    {12, 5.27, 1194.45},  {12, 2.08, 4694},               {11, 0.77, 553.57},          {10, 1.3, 6286.6},
    {10, 4.24, 1349.87},  {9, 2.7, 242.73},               {9, 5.64, 951.72},           {8, 5.3, 2352.87},
    {6, 2.65, 9437.76},   {6, 4.67, 4690.48}};
constexpr Term kL2[] = {{52919, 0, 0},      {8720, 1.0721, 6283.0758}, {309, 0.867, 12566.152}, {27, 0.05, 3.52},
                        {16, 5.19, 26.3},   {16, 3.68, 155.42},        {10, 0.76, 18849.23},    {9, 2.06, 77713.77},
                        {7, 0.83, 775.52},  {5, 4.66, 1577.34},        {4, 1.03, 7.11},         {4, 3.44, 5573.14},
                        {3, 5.14, 796.3},   {3, 6.05, 5507.55},        {3, 1.19, 242.73},       {3, 6.12, 529.69},
                        {3, 0.31, 398.15},  {3, 2.28, 553.57},         {2, 4.38, 5223.69},      {2, 3.75, 0.98}};
constexpr Term kL3[] = {{289, 5.844, 6283.076}, {35, 0, 0},         {17, 5.49, 12566.15}, {3, 5.2, 155.42},
                        {1, 4.72, 3.52},        {1, 5.3, 18849.23}, {1, 5.97, 242.73}};
constexpr Term kL4[] = {{114, 3.142, 0}, {8, 4.13, 6283.08}, {1, 3.84, 12566.15}};
constexpr Term kL5[] = {{1, 3.14, 0}};
constexpr Term kB0[] = {{280, 3.199, 84334.662}, {102, 5.422, 5507.553}, {80, 3.88, 5223.69},
                        {44, 3.7, 2352.87},      {32, 4, 1577.34}};
constexpr Term kB1[] = {{9, 3.9, 5507.55}, {6, 1.73, 5223.69}};
constexpr Term kR0[] = {
    {100013989, 0, 0},        {1670700, 3.0984635, 6283.07585}, {13956, 3.05525, 12566.1517},
    {3084, 5.1985, 77713.7715}, {1628, 1.1739, 5753.3849},      {1576, 2.8469, 7860.4194},
    {925, 5.453, 11506.77},   {542, 4.564, 3930.21},            {472, 3.661, 5884.927},
    {346, 0.964, 5507.553},   {329, 5.9, 5223.694},             {307, 0.299, 5573.143},
    {243, 4.273, 11790.629},  {212, 5.847, 1577.344},           {186, 5.022, 10977.079},
    {175, 3.012, 18849.228},  {110, 5.055, 5486.778},           {98, 0.89, 6069.78},
    {86, 5.69, 15720.84},     {86, 1.27, 161000.69},            {65, 0.27, 17260.15},
    {63, 0.92, 529.69},       {57, 2.01, 83996.85},             {56, 5.24, 71430.7},
    {49, 3.25, 2544.31},      {47, 2.58, 775.52},               {45, 5.54, 9437.76},
    {43, 6.01, 6275.96},      {39, 5.36, 4694},                 {38, 2.39, 8827.39},
    {37, 0.83, 19651.05},     {37, 4.9, 12139.55},              {36, 1.67, 12036.46},
    {35, 1.84, 2942.46},      {33, 0.24, 7084.9},               {32, 0.18, 5088.63},
    {32, 1.78, 398.15},       {28, 1.21, 6286.6},               {28, 1.9, 6279.55},
    {26, 4.59, 10447.39}};
constexpr Term kR1[] = {{103019, 1.10749, 6283.07585}, {1721, 1.0644, 12566.1517}, {702, 3.142, 0},
                        {32, 1.02, 18849.23},          {31, 2.84, 5507.55},        {25, 1.32, 5223.69},
                        {18, 1.42, 1577.34},           {10, 5.91, 10977.08},       {9, 1.42, 6275.96},
                        {9, 0.27, 5486.78}};
constexpr Term kR2[] = {{4359, 5.7846, 6283.0758}, {124, 5.579, 12566.152}, {12, 3.14, 0},
                        {9, 3.63, 77713.77},       {6, 1.87, 5573.14},      {3, 5.47, 18849.23}};
constexpr Term kR3[] = {{145, 4.273, 6283.076}, {7, 3.92, 12566.15}};
constexpr Term kR4[] = {{4, 2.56, 6283.08}};

template <size_t N>
double series(const Term (&terms)[N], double jme) {
  double s = 0;
  for (const Term& t : terms) s += t.a * std::cos(t.b + t.c * jme);
  return s;
}

// Table A4.3: periodic terms for the nutation in longitude and obliquity (0.0001"), with the
// multipliers of D, M, M', F, Ω.
struct NutationTerm {
  signed char y[5];
  double a, b, c, d;  // Δψ: (a + b·JCE) sin(Σ), Δε: (c + d·JCE) cos(Σ)
};
constexpr NutationTerm kNutation[] = {
    {{0, 0, 0, 0, 1}, -171996, -174.2, 92025, 8.9}, {{-2, 0, 0, 2, 2}, -13187, -1.6, 5736, -3.1},
    {{0, 0, 0, 2, 2}, -2274, -0.2, 977, -0.5},       {{0, 0, 0, 0, 2}, 2062, 0.2, -895, 0.5},
    {{0, 1, 0, 0, 0}, 1426, -3.4, 54, -0.1},         {{0, 0, 1, 0, 0}, 712, 0.1, -7, 0},
    {{-2, 1, 0, 2, 2}, -517, 1.2, 224, -0.6},        {{0, 0, 0, 2, 1}, -386, -0.4, 200, 0},
    {{0, 0, 1, 2, 2}, -301, 0, 129, -0.1},           {{-2, -1, 0, 2, 2}, 217, -0.5, -95, 0.3},
    {{-2, 0, 1, 0, 0}, -158, 0, 0, 0},               {{-2, 0, 0, 2, 1}, 129, 0.1, -70, 0},
    {{0, 0, -1, 2, 2}, 123, 0, -53, 0},              {{2, 0, 0, 0, 0}, 63, 0, 0, 0},
    {{0, 0, 1, 0, 1}, 63, 0.1, -33, 0},              {{2, 0, -1, 2, 2}, -59, 0, 26, 0},
    {{0, 0, -1, 0, 1}, -58, -0.1, 32, 0},            {{0, 0, 1, 2, 1}, -51, 0, 27, 0},
    {{-2, 0, 2, 0, 0}, 48, 0, 0, 0},                 {{0, 0, -2, 2, 1}, 46, 0, -24, 0},
    {{2, 0, 0, 2, 2}, -38, 0, 16, 0},                {{0, 0, 2, 2, 2}, -31, 0, 13, 0},
    {{0, 0, 2, 0, 0}, 29, 0, 0, 0},                  {{-2, 0, 1, 2, 2}, 29, 0, -12, 0},
    {{0, 0, 0, 2, 0}, 26, 0, 0, 0},                  {{-2, 0, 0, 2, 0}, -22, 0, 0, 0},
    {{0, 0, -1, 2, 1}, 21, 0, -10, 0},               {{0, 2, 0, 0, 0}, 17, -0.1, 0, 0},
    {{2, 0, -1, 0, 1}, 16, 0, -8, 0},                {{-2, 2, 0, 2, 2}, -16, 0.1, 7, 0},
    {{0, 1, 0, 0, 1}, -15, 0, 9, 0},                 {{-2, 0, 1, 0, 1}, -13, 0, 7, 0},
    {{0, -1, 0, 0, 1}, -12, 0, 6, 0},                {{0, 0, 2, -2, 0}, 11, 0, 0, 0},
    {{2, 0, -1, 2, 1}, -10, 0, 5, 0},                {{2, 0, 1, 2, 2}, -8, 0, 3, 0},
    {{0, 1, 0, 2, 2}, 7, 0, -3, 0},                  {{-2, 1, 1, 0, 0}, -7, 0, 0, 0},
    {{0, -1, 0, 2, 2}, -7, 0, 3, 0},                 {{2, 0, 0, 2, 1}, -7, 0, 3, 0},
    {{2, 0, 1, 0, 0}, 6, 0, 0, 0},                   {{-2, 0, 2, 2, 2}, 6, 0, -3, 0},
    {{-2, 0, 1, 2, 1}, 6, 0, -3, 0},                 {{2, 0, -2, 0, 1}, -6, 0, 3, 0},
    {{2, 0, 0, 0, 1}, -6, 0, 3, 0},                  {{0, -1, 1, 0, 0}, 5, 0, 0, 0},
    {{-2, -1, 0, 2, 1}, -5, 0, 3, 0},                {{-2, 0, 0, 0, 1}, -5, 0, 3, 0},
    {{0, 0, 2, 2, 1}, -5, 0, 3, 0},                  {{-2, 0, 2, 0, 1}, 4, 0, 0, 0},
    {{-2, 1, 0, 2, 1}, 4, 0, 0, 0},                  {{0, 0, 1, -2, 0}, 4, 0, 0, 0},
    {{-1, 0, 1, 0, 0}, -4, 0, 0, 0},                 {{-2, 1, 0, 0, 0}, -4, 0, 0, 0},
    {{1, 0, 0, 0, 0}, -4, 0, 0, 0},                  {{0, 0, 1, 2, 0}, 3, 0, 0, 0},
    {{0, 0, -2, 2, 2}, -3, 0, 0, 0},                 {{-1, -1, 1, 0, 0}, -3, 0, 0, 0},
    {{0, 1, 1, 0, 0}, -3, 0, 0, 0},                  {{0, -1, 1, 2, 2}, -3, 0, 0, 0},
    {{2, -1, -1, 2, 2}, -3, 0, 0, 0},                {{0, 0, 3, 2, 2}, -3, 0, 0, 0},
    {{2, -1, 0, 2, 2}, -3, 0, 0, 0}};
static_assert(std::size(kNutation) == 63);

double third_order(double a, double b, double c, double d, double x) { return ((d * x + c) * x + b) * x + a; }

void check_finite(std::string_view name, double v) {
  if (!std::isfinite(v)) throw std::invalid_argument(fmt::format("SPA input {} = {} is not a finite number", name, v));
}
void check_range(std::string_view name, double v, double lo, double hi, std::string_view unit) {
  check_finite(name, v);
  if (v < lo || v > hi)
    throw std::invalid_argument(
        fmt::format("SPA input {} = {} {} is out of range: allowed {} .. {} {}", name, v, unit, lo, hi, unit));
}

}  // namespace

double spa_refraction_deg(double e0, double pressure_mbar, double temperature_c, double atmos_refract_deg) {
  if (e0 < -1.0 * (0.26667 + atmos_refract_deg)) return 0.0;  // upper limb below the refracted horizon
  return (pressure_mbar / 1010.0) * (283.0 / (273.0 + temperature_c)) * 1.02 /
         (60.0 * std::tan(rad(e0 + 10.3 / (e0 + 5.11))));
}

void validate_spa_input(const SpaInput& in) {
  const int year = in.time.civil().year;
  if (year < -2000 || year > 6000)
    throw std::invalid_argument(
        fmt::format("SPA input time {} (year {}) is out of range: allowed years -2000 .. 6000", in.time.iso8601(), year));
  check_range("latitude", in.latitude_deg, -90, 90, "deg");
  check_range("longitude", in.longitude_deg, -180, 180, "deg");
  check_finite("delta_ut1", in.delta_ut1_s);
  if (std::abs(in.delta_ut1_s) >= 1)
    throw std::invalid_argument(
        fmt::format("SPA input delta_ut1 = {} s is out of range: allowed -1 < delta_ut1 < 1 s", in.delta_ut1_s));
  check_range("delta_t", in.delta_t_s, -8000, 8000, "s");
  check_range("elevation", in.elevation_m, -6'500'000, 1e9, "m");
  check_range("pressure", in.pressure_mbar, 0, 5000, "mbar");
  check_range("temperature", in.temperature_c, -273, 6000, "C");
  check_range("atmos_refract", in.atmos_refract_deg, -5, 5, "deg");
}

SpaResult spa_sun_position(const SpaInput& in) {
  validate_spa_input(in);
  SpaResult r;

  // 3.1 Julian Day (UT1 = UTC + ΔUT1), Julian Ephemeris Day (TT = UT1 + ΔT), centuries, millennia.
  const JulianDate jd = in.time.julian_date(in.delta_ut1_s);
  const JulianDate jde = in.time.julian_date(in.delta_ut1_s + in.delta_t_s);
  const double d_ut = jd.days_since_j2000();
  r.jd = jd.value();
  r.jde = jde.value();
  r.jc = d_ut / 36525.0;
  r.jce = jde.days_since_j2000() / 36525.0;
  r.jme = r.jce / 10.0;
  const double jme = r.jme;

  // 3.2 Heliocentric longitude, latitude and radius vector: Σ X_i·JME^i / 1e8.
  const double l[] = {series(kL0, jme), series(kL1, jme), series(kL2, jme),
                      series(kL3, jme), series(kL4, jme), series(kL5, jme)};
  const double l_rad = (((((l[5] * jme + l[4]) * jme + l[3]) * jme + l[2]) * jme + l[1]) * jme + l[0]) / 1e8;
  r.L = limit_degrees(deg(l_rad));
  const double b_rad = (series(kB0, jme) + series(kB1, jme) * jme) / 1e8;
  r.B = deg(b_rad);
  const double rr[] = {series(kR0, jme), series(kR1, jme), series(kR2, jme), series(kR3, jme), series(kR4, jme)};
  r.R = ((((rr[4] * jme + rr[3]) * jme + rr[2]) * jme + rr[1]) * jme + rr[0]) / 1e8;

  // 3.3 Geocentric longitude and latitude.
  r.theta = limit_degrees(r.L + 180.0);
  r.beta = -r.B;

  // 3.4 Nutation in longitude and obliquity.
  const double jce = r.jce;
  r.x0 = third_order(297.85036, 445267.111480, -0.0019142, 1.0 / 189474.0, jce);
  r.x1 = third_order(357.52772, 35999.050340, -0.0001603, -1.0 / 300000.0, jce);
  r.x2 = third_order(134.96298, 477198.867398, 0.0086972, 1.0 / 56250.0, jce);
  r.x3 = third_order(93.27191, 483202.017538, -0.0036825, 1.0 / 327270.0, jce);
  r.x4 = third_order(125.04452, -1934.136261, 0.0020708, 1.0 / 450000.0, jce);
  const double x[] = {r.x0, r.x1, r.x2, r.x3, r.x4};
  double sum_psi = 0, sum_eps = 0;
  for (const NutationTerm& t : kNutation) {
    const double arg = rad(t.y[0] * x[0] + t.y[1] * x[1] + t.y[2] * x[2] + t.y[3] * x[3] + t.y[4] * x[4]);
    sum_psi += (t.a + t.b * jce) * std::sin(arg);
    sum_eps += (t.c + t.d * jce) * std::cos(arg);
  }
  r.del_psi = sum_psi / 36'000'000.0;  // 0.0001" -> degrees
  r.del_epsilon = sum_eps / 36'000'000.0;

  // 3.5 True obliquity of the ecliptic.
  const double u = jme / 10.0;
  double eps0 = 0;
  for (const double c : {2.45, 5.79, 27.87, 7.12, -39.05, -249.67, -51.38, 1999.25, -1.55, -4680.93, 84381.448})
    eps0 = eps0 * u + c;
  r.epsilon0 = eps0;
  r.epsilon = eps0 / 3600.0 + r.del_epsilon;

  // 3.6 Aberration correction, 3.7 apparent sun longitude.
  r.del_tau = -20.4898 / (3600.0 * r.R);
  r.lamda = r.theta + r.del_psi + r.del_tau;

  // 3.8 Apparent sidereal time at Greenwich.
  r.nu0 = limit_degrees(280.46061837 + 360.98564736629 * d_ut + r.jc * r.jc * (0.000387933 - r.jc / 38710000.0));
  r.nu = r.nu0 + r.del_psi * std::cos(rad(r.epsilon));

  // 3.9 Geocentric right ascension, 3.10 declination.
  const double lamda_rad = rad(r.lamda), eps_rad = rad(r.epsilon), beta_rad = rad(r.beta);
  r.alpha = limit_degrees(deg(std::atan2(std::sin(lamda_rad) * std::cos(eps_rad) - std::tan(beta_rad) * std::sin(eps_rad),
                                         std::cos(lamda_rad))));
  r.delta = deg(std::asin(std::sin(beta_rad) * std::cos(eps_rad) +
                          std::cos(beta_rad) * std::sin(eps_rad) * std::sin(lamda_rad)));

  // 3.11 Observer local hour angle.
  r.h = limit_degrees(r.nu + in.longitude_deg - r.alpha);

  // 3.12 Topocentric right ascension and declination (parallax of an observer on the ellipsoid).
  r.xi = 8.794 / (3600.0 * r.R);
  const double lat = rad(in.latitude_deg), xi = rad(r.xi), h = rad(r.h), delta = rad(r.delta);
  const double uu = std::atan(0.99664719 * std::tan(lat));
  const double xx = std::cos(uu) + in.elevation_m / 6378140.0 * std::cos(lat);
  const double yy = 0.99664719 * std::sin(uu) + in.elevation_m / 6378140.0 * std::sin(lat);
  const double del_alpha = std::atan2(-xx * std::sin(xi) * std::sin(h), std::cos(delta) - xx * std::sin(xi) * std::cos(h));
  const double delta_prime = std::atan2((std::sin(delta) - yy * std::sin(xi)) * std::cos(del_alpha),
                                        std::cos(delta) - xx * std::sin(xi) * std::cos(h));
  r.del_alpha = deg(del_alpha);
  r.delta_prime = deg(delta_prime);
  r.alpha_prime = r.alpha + r.del_alpha;

  // 3.13 Topocentric local hour angle.
  r.h_prime = r.h - r.del_alpha;

  // 3.14 Topocentric zenith angle: elevation without refraction, refraction, apparent elevation.
  const double h_prime = rad(r.h_prime);
  r.e0 = deg(std::asin(std::sin(lat) * std::sin(delta_prime) + std::cos(lat) * std::cos(delta_prime) * std::cos(h_prime)));
  r.del_e = spa_refraction_deg(r.e0, in.pressure_mbar, in.temperature_c, in.atmos_refract_deg);
  r.e = r.e0 + r.del_e;
  r.zenith = 90.0 - r.e;
  r.zenith_geometric = 90.0 - r.e0;

  // 3.15 Topocentric azimuth: astronomers' (from south, westward) and navigators' (from north, eastward).
  r.azimuth_astro = limit_degrees(deg(std::atan2(
      std::sin(h_prime), std::cos(h_prime) * std::sin(lat) - std::tan(delta_prime) * std::cos(lat))));
  r.azimuth = limit_degrees(r.azimuth_astro + 180.0);
  return r;
}

}  // namespace arpipe
