/*
 * The DRTM paper's arena (Pang et al. 2023, Secs. 2.3 and 3.1; drtm_task_allocation.md) as ARGoS
 * loop functions, so that the ARGoS foraging example's controller (ilpincy/argos3-examples,
 * controllers/footbot_foraging, built unchanged) forages in it. Ours: written for swarmforage's
 * reference runs (reference/drtm_argos.py builds and runs it); it only includes the example's
 * controller header, to hand the controller its food as the example's own loop functions do.
 *
 * What differs from the example's loop functions (foraging_loop_functions.cpp), and why:
 *  - the nest is a disc of radius nest_radius at the arena's centre (the paper's grey circle,
 *    Fig. 4), not the strip x < -1; the floor is grey inside it, which is how the controller
 *    knows it is in the nest (its back ground sensors);
 *  - food lies uniformly where swarmforage's drtm.yaml puts it: |x|, |y| <= L/2 - margin and at
 *    least clearance outside the nest; a delivered token reappears there at once (Sec. 2.3);
 *  - robots start with their centres uniformly in the nest disc (Sec. 2.3: "placed in the nest
 *    randomly");
 *  - it logs, every tick, what swarmforage's nest ledger needs: robots not resting (the
 *    example's "walking" robots, charged one unit a tick), tokens dropped in the nest (F_t),
 *    deliveries booked when the robot that dropped them comes to rest (the ledger's DEPOSITED), and
 *    obstacle-avoidance events (OAEs): one per episode, an episode being the ticks in which the
 *    controller's diffusion (its DiffusionVector) turns away from an obstacle, read from the
 *    same proximity readings with the same two thresholds. The energy ledger itself is computed
 *    from this log by drtm_argos.py with swarmforage's own NestLedger.
 */
#include <controllers/footbot_foraging/footbot_foraging.h>

#include <argos3/core/simulator/loop_functions.h>
#include <argos3/core/simulator/simulator.h>
#include <argos3/core/simulator/entity/floor_entity.h>
#include <argos3/core/utility/math/rng.h>
#include <argos3/core/utility/math/vector2.h>
#include <argos3/plugins/robots/foot-bot/control_interface/ci_footbot_proximity_sensor.h>
#include <argos3/plugins/robots/foot-bot/simulator/footbot_entity.h>

#include <fstream>
#include <vector>

using namespace argos;

class CDrtmArenaLoopFunctions : public CLoopFunctions {

public:

   void Init(TConfigurationNode& t_node) override {
      TConfigurationNode& tArena = GetNode(t_node, "drtm_arena");
      Real fHalf, fMargin, fClearance, fPickup, fStraightDeg;
      UInt32 unItems;
      GetNodeAttribute(tArena, "half_side", fHalf);
      GetNodeAttribute(tArena, "nest_radius", m_fNestRadius);
      GetNodeAttribute(tArena, "items", unItems);
      GetNodeAttribute(tArena, "margin", fMargin);
      GetNodeAttribute(tArena, "clearance", fClearance);
      GetNodeAttribute(tArena, "pickup_radius", fPickup);
      GetNodeAttribute(tArena, "go_straight_deg", fStraightDeg);
      GetNodeAttribute(tArena, "delta", m_fDelta);
      GetNodeAttribute(tArena, "output", m_strOutput);
      m_fPickup2 = fPickup * fPickup;
      m_cSide.Set(-(fHalf - fMargin), fHalf - fMargin);
      m_fClear2 = (m_fNestRadius + fClearance) * (m_fNestRadius + fClearance);
      m_cStraight.Set(-ToRadians(CDegrees(fStraightDeg)), ToRadians(CDegrees(fStraightDeg)));
      m_pcFloor = &GetSpace().GetFloorEntity();
      m_pcRNG = CRandom::CreateRNG("argos");
      for(UInt32 i = 0; i < unItems; ++i) m_cFood.push_back(FoodPosition());
      PlaceRobotsInNest();
      CSpace::TMapPerType& tBots = GetSpace().GetEntitiesByType("foot-bot");
      m_vecRobots.resize(tBots.size());
      m_cOutput.open(m_strOutput.c_str(), std::ios_base::trunc | std::ios_base::out);
      m_cOutput << "# clock\tactive\tdrops\tdeliveries\toaes\toaes_returning" << std::endl;
   }

   void Destroy() override {
      m_cOutput.close();
   }

   CColor GetFloorColor(const CVector2& c_pos) override {
      if(c_pos.SquareLength() < m_fNestRadius * m_fNestRadius) return CColor::GRAY50;
      for(const CVector2& cFood : m_cFood) {
         if((c_pos - cFood).SquareLength() < m_fPickup2) return CColor::BLACK;
      }
      return CColor::WHITE;
   }

   /* Pick-up and drop, before the controllers run (as the example does): a robot without food
      whose centre is within the pick-up radius of a token outside the nest takes it; a robot
      with food whose centre is in the nest drops it, and the token reappears elsewhere. */
   void PreStep() override {
      for(auto& tPair : GetSpace().GetEntitiesByType("foot-bot")) {
         CFootBotEntity& cBot = *any_cast<CFootBotEntity*>(tPair.second);
         CFootBotForaging& cCtrl = dynamic_cast<CFootBotForaging&>(cBot.GetControllableEntity().GetController());
         const CVector3& cP = cBot.GetEmbodiedEntity().GetOriginAnchor().Position;
         CVector2 cPos(cP.GetX(), cP.GetY());
         CFootBotForaging::SFoodData& sFood = cCtrl.GetFoodData();
         bool bInNest = cPos.SquareLength() < m_fNestRadius * m_fNestRadius;
         if(sFood.HasFoodItem) {
            if(bInNest) {
               m_cFood[sFood.FoodItemIdx] = FoodPosition();
               sFood.HasFoodItem = false;
               sFood.FoodItemIdx = 0;
               ++sFood.TotalFoodItems;
               ++m_unDrops;
               m_pcFloor->SetChanged();
            }
         }
         else if(!bInNest) {
            for(size_t i = 0; i < m_cFood.size(); ++i) {
               if((cPos - m_cFood[i]).SquareLength() < m_fPickup2) {
                  m_cFood[i].Set(100.0, 100.0);
                  sFood.HasFoodItem = true;
                  sFood.FoodItemIdx = i;
                  m_pcFloor->SetChanged();
                  break;
               }
            }
         }
      }
   }

   /* After the controllers ran: count the robots not resting, the deliveries booked at rest and
      the OAE episodes, and log the tick. */
   void PostStep() override {
      UInt32 unActive = 0;
      size_t i = 0;
      for(auto& tPair : GetSpace().GetEntitiesByType("foot-bot")) {
         CFootBotEntity& cBot = *any_cast<CFootBotEntity*>(tPair.second);
         CFootBotForaging& cCtrl = dynamic_cast<CFootBotForaging&>(cBot.GetControllableEntity().GetController());
         SRobot& sR = m_vecRobots[i++];
         size_t unTotal = cCtrl.GetFoodData().TotalFoodItems;
         if(cCtrl.IsResting()) {
            if(!sR.Resting) m_unDeliveries += unTotal - sR.TotalAtLeave;
            sR.Resting = true;
            sR.Avoiding = false;
            continue;
         }
         if(sR.Resting) sR.TotalAtLeave = unTotal;
         sR.Resting = false;
         ++unActive;
         bool bAvoiding = Avoiding(cCtrl);
         if(bAvoiding && !sR.Avoiding) {
            ++m_unOAEs;
            if(cCtrl.IsReturningToNest()) ++m_unOAEsReturning;
         }
         sR.Avoiding = bAvoiding;
      }
      m_cOutput << GetSpace().GetSimulationClock() << "\t" << unActive << "\t" << m_unDrops << "\t"
                << m_unDeliveries << "\t" << m_unOAEs << "\t" << m_unOAEsReturning << "\n";
   }

private:

   struct SRobot {
      bool Resting = true;
      bool Avoiding = false;
      size_t TotalAtLeave = 0;
   };

   /* The example's DiffusionVector test: the readings summed as vectors go straight only when
      their angle is within the go-straight range and their length is below delta. */
   bool Avoiding(CFootBotForaging& c_ctrl) {
      const CCI_FootBotProximitySensor::TReadings& tReads =
         c_ctrl.GetSensor<CCI_FootBotProximitySensor>("footbot_proximity")->GetReadings();
      CVector2 cSum;
      for(const auto& sRead : tReads) cSum += CVector2(sRead.Value, sRead.Angle);
      return !(m_cStraight.WithinMinBoundIncludedMaxBoundIncluded(cSum.Angle()) && cSum.Length() < m_fDelta);
   }

   CVector2 FoodPosition() {
      CVector2 cPos;
      do {
         cPos.Set(m_pcRNG->Uniform(m_cSide), m_pcRNG->Uniform(m_cSide));
      } while(cPos.SquareLength() < m_fClear2);
      return cPos;
   }

   void PlaceRobotsInNest() {
      CRange<Real> cDisc(-m_fNestRadius, m_fNestRadius);
      for(auto& tPair : GetSpace().GetEntitiesByType("foot-bot")) {
         CFootBotEntity& cBot = *any_cast<CFootBotEntity*>(tPair.second);
         for(UInt32 unTrial = 0; unTrial < 10000; ++unTrial) {
            CVector2 cPos(m_pcRNG->Uniform(cDisc), m_pcRNG->Uniform(cDisc));
            if(cPos.SquareLength() >= m_fNestRadius * m_fNestRadius) continue;
            CQuaternion cYaw;
            cYaw.FromEulerAngles(m_pcRNG->Uniform(CRadians::UNSIGNED_RANGE), CRadians::ZERO, CRadians::ZERO);
            if(MoveEntity(cBot.GetEmbodiedEntity(), CVector3(cPos.GetX(), cPos.GetY(), 0.0), cYaw)) break;
            if(unTrial == 9999) THROW_ARGOSEXCEPTION("cannot place " << cBot.GetId() << " in the nest");
         }
      }
   }

   Real m_fNestRadius = 0.75, m_fPickup2 = 0.01, m_fClear2 = 0.0, m_fDelta = 0.1;
   CRange<Real> m_cSide;
   CRange<CRadians> m_cStraight;
   CFloorEntity* m_pcFloor = nullptr;
   CRandom::CRNG* m_pcRNG = nullptr;
   std::vector<CVector2> m_cFood;
   std::vector<SRobot> m_vecRobots;
   UInt32 m_unDrops = 0, m_unDeliveries = 0, m_unOAEs = 0, m_unOAEsReturning = 0;
   std::string m_strOutput;
   std::ofstream m_cOutput;
};

REGISTER_LOOP_FUNCTIONS(CDrtmArenaLoopFunctions, "drtm_arena_loop_functions")
