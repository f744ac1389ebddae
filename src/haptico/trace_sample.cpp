#include "uh/haptico/trace_sample.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

namespace uh::haptico {

void write_trace_header(std::ostream& out) {
  out << "tick_time_s,device_time_s,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,buttons,status,"
         "req_fx,req_fy,req_fz,req_tx,req_ty,req_tz,fx,fy,fz,tx,ty,tz,flags\n";
}

void write_trace_row(std::ostream& out, const TraceSample& s) {
  const DeviceState& st = s.state;
  fmt::print(out, "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
             s.tick_time_s, st.time_s, st.position.x, st.position.y, st.position.z, st.orientation.w,
             st.orientation.x, st.orientation.y, st.orientation.z, st.linear_velocity.x, st.linear_velocity.y,
             st.linear_velocity.z, st.angular_velocity.x, st.angular_velocity.y, st.angular_velocity.z, st.buttons,
             static_cast<int>(st.status), s.requested.force.x, s.requested.force.y, s.requested.force.z,
             s.requested.torque.x, s.requested.torque.y, s.requested.torque.z, s.sent.force.x, s.sent.force.y,
             s.sent.force.z, s.sent.torque.x, s.sent.torque.y, s.sent.torque.z, s.flags);
}

}  // namespace uh::haptico
