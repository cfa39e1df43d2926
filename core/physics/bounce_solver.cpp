// The bounce fix: after Bullet has set up the contact rows, the rows of bouncing contacts with a
// positive gap get back the gap / dt that Bullet took off their target velocity.
#include "core/physics/bounce_solver.h"

namespace arpipe {

namespace {

btVector3 bounce_solver_point_velocity(const btSolverBody& body, const btVector3& world_point) {
  btVector3 v(0, 0, 0);
  if (body.m_originalBody)
    body.getVelocityInLocalPointNoDelta(world_point - body.m_originalBody->getWorldTransform().getOrigin(), v);
  return v;
}

}  // namespace

void BounceSolver::convertContacts(btPersistentManifold** manifolds, int count, const btContactSolverInfo& info) {
  btSequentialImpulseConstraintSolver::convertContacts(manifolds, count, info);
  for (int i = 0; i < m_tmpSolverContactConstraintPool.size(); ++i) {
    btSolverConstraint& row = m_tmpSolverContactConstraintPool[i];
    const auto* cp = static_cast<const btManifoldPoint*>(row.m_originalContactPoint);
    const btScalar gap = cp->getDistance();
    if (!(gap > 0) || !(cp->m_combinedRestitution > 0)) continue;
    // The same approach velocity and restitution rule as Bullet's row setup.
    const btVector3 va = bounce_solver_point_velocity(m_tmpSolverBodyPool[row.m_solverBodyIdA], cp->getPositionWorldOnA());
    const btVector3 vb = bounce_solver_point_velocity(m_tmpSolverBodyPool[row.m_solverBodyIdB], cp->getPositionWorldOnB());
    const btScalar approach = cp->m_normalWorldOnB.dot(va - vb);
    if (restitutionCurve(approach, cp->m_combinedRestitution, info.m_restitutionVelocityThreshold) <= 0) continue;
    row.m_rhs += gap * (btScalar(1) / info.m_timeStep) * row.m_jacDiagABInv;
  }
}

}  // namespace arpipe
