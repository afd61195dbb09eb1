use timpanist::mocap::db::MotionDb;
use timpanist::body::Joint;
fn main() {
    let db = MotionDb::load(std::path::Path::new("/tmp/db1")).unwrap();
    for (ti, t) in db.takes.iter().enumerate().step_by(7) {
        let poses = t.joints.as_ref().unwrap();
        let mut line = format!("{:40}", db.index.takes[ti].file);
        for j in [Joint::ShoulderR, Joint::ElbowR, Joint::WristR, Joint::GripR, Joint::GripL, Joint::Trunk] {
            let a: Vec<f64> = poses.iter().map(|p| p[j.index()].angle_between(glam::DQuat::IDENTITY).to_degrees()).collect();
            let lo = a.iter().cloned().fold(f64::INFINITY, f64::min); let hi = a.iter().cloned().fold(0.0, f64::max);
            line += &format!(" {}:{:.0}-{:.0}", j.name(), lo, hi);
        }
        println!("{line}");
    }
}
