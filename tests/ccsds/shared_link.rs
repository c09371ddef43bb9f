//! What the conformance statements (spec/ccsds/pics/) claim and no other test reached: several
//! robots' master channels on one server board's link (TC frames demultiplexed by spacecraft
//! ID, TM frames of each robot multiplexed onto the one downlink), and FOP-1's directives that
//! set T1 and the timeout type.

use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::link::clcw::Clcw;
use mmic::link::fop::{
    Directive, DirectiveResponse, Fop, FopConfig, FopOutput, FrameData, TimeoutType,
};
use mmic::link::tc_frame::{MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
use mmic::link::tm_frame::{TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
use mmic::link::FrameKind;
use mmic::node::server::frames::{FrameConfig, FrameGateway};
use mmic::units::BoardNumber;

/// An AD frame N(S) = 0 to spacecraft `scid` carrying TC(17,1) to APID `apid`.
fn ping_frame(scid: u16, apid: u16) -> Vec<u8> {
    let mut ping = [0u8; 13];
    TcRepr {
        apid: Apid::new(apid).unwrap(),
        seq_count: SeqCount::new(0).unwrap(),
        ..crate::ccsds::ping()
    }
    .emit(&mut ping)
    .unwrap();
    let frame = TcFrameRepr {
        spacecraft_id: SpacecraftId::new(scid).unwrap(),
        vcid: Vcid::new(0).unwrap(),
        seq: 0,
        content: TcContent::Ad {
            map_id: Some(MapId::new(0).unwrap()),
            data: &ping,
        },
    };
    let mut buf = [0u8; 64];
    let n = frame.emit(&mut buf).unwrap();
    buf[..n].to_vec()
}

// req: 232.0-B-4/TC-34, 232.0-B-4/TC-35, 132.0-B-3/TM-60, 132.0-B-3/TM-72, 132.0-B-3/TM-98
// req: 232.1-B-2/CLCW-3, 232.1-B-2/FARM-10
#[test]
fn two_robots_share_one_link_each_on_its_own_master_channel() {
    let two = BoardNumber::new(2).unwrap();
    let mut g: FrameGateway<2, 4, 8, 1024> = FrameGateway::new(FrameConfig::default());
    assert!(g.add(BoardNumber::ONE) && g.add(two));
    // TC: each frame goes to the robot its spacecraft ID names; an unserved one to none.
    for (scid, robot) in [(0x101, BoardNumber::ONE), (0x102, two)] {
        let v = g.tc_frame(0, &ping_frame(scid, scid));
        assert_eq!((v.robot, v.accepted), (Some(robot), 1), "SCID {scid:#x}");
    }
    let v = g.tc_frame(0, &ping_frame(0x103, 0x103));
    assert_eq!(
        (v.robot, v.accepted),
        (None, 0),
        "a spacecraft the board does not serve"
    );
    assert!(v.verdict.is_err());
    assert_eq!(g.farm(BoardNumber::ONE).unwrap().vr(), 1);
    assert_eq!(g.farm(two).unwrap().vr(), 1);
    for e in g.durable_due::<8>() {
        assert!(g.durable_written(&e));
    }
    // TM: both robots' frames leave on the one channel, the first robot added first, each
    // under its own spacecraft ID with its own CLCW.
    let mut order = Vec::new();
    let mut tm = [0u8; TM_FRAME_LEN];
    while let Some((board, len)) = g.frame(0, &mut tm) {
        let scid = 0x100 + u16::from(board.get());
        let params = TmFrameParams::mission(scid).unwrap();
        let f = TmFrameRepr::parse(&tm[..len], &params).unwrap();
        assert_eq!(f.spacecraft_id, scid);
        let clcw = Clcw::parse(&f.ocf.unwrap()).unwrap();
        assert_eq!(clcw.report_value, 1);
        assert!(
            !clcw.no_rf_available && !clcw.no_bit_lock,
            "the server board hears the ground"
        );
        order.push(board);
        assert!(order.len() < 16, "frames keep coming");
    }
    assert_eq!(order.first(), Some(&BoardNumber::ONE));
    assert!(
        order.contains(&two),
        "robot 2's frames share the channel: {order:?}"
    );
}

// req: 232.1-B-2/FOP-10
#[test]
fn set_t1_and_set_timeout_type_take_effect() {
    let mut fop: Fop<u8, 10> = Fop::new(FopConfig::MISSION);
    let mut out = |_: FopOutput<u8>| {};
    assert_eq!(
        fop.directive(Directive::SetT1(500), 0, &mut out),
        DirectiveResponse::Confirmed
    );
    assert_eq!(
        fop.directive(Directive::SetTimeoutType(TimeoutType::Suspend), 0, &mut out),
        DirectiveResponse::Confirmed
    );
    assert_eq!(
        (fop.config().t1_ms, fop.config().timeout_type),
        (500, TimeoutType::Suspend)
    );
    // T1 now runs 500 ms from the frame's transmission.
    fop.directive(Directive::InitiateWithoutClcw, 0, &mut out);
    assert_eq!(fop.transfer_ad(1, 100, &mut out), Ok(()));
    assert_eq!(fop.timer_deadline(), Some(600));
    // And a window or limit out of range is refused, the parameters unchanged.
    assert_eq!(
        fop.directive(Directive::SetWindow(0), 0, &mut out),
        DirectiveResponse::Rejected
    );
    assert_eq!(
        fop.directive(Directive::SetTxLimit(0), 0, &mut out),
        DirectiveResponse::Rejected
    );
    assert_eq!(fop.config().window, FopConfig::MISSION.window);
}

// req: 232.1-B-2/FOP-12
#[test]
fn bd_frames_go_at_once_beside_the_ad_service() {
    let mut fop: Fop<u8, 10> = Fop::new(FopConfig::MISSION);
    let mut outs = Vec::new();
    // Before any Initiate directive, and while AD frames are outstanding, a BD frame goes.
    fop.transfer_bd(7, &mut |o| outs.push(o));
    fop.directive(Directive::InitiateWithoutClcw, 0, &mut |o| outs.push(o));
    assert_eq!(fop.transfer_ad(1, 0, &mut |o| outs.push(o)), Ok(()));
    fop.transfer_bd(8, &mut |o| outs.push(o));
    let bd: Vec<u8> = outs
        .iter()
        .filter_map(|o| match o {
            FopOutput::Transmit(f) if f.kind == FrameKind::Bd => match f.data {
                FrameData::Fdu(p) => Some(p),
                _ => None,
            },
            _ => None,
        })
        .collect();
    assert_eq!(bd, [7, 8]);
    assert_eq!(
        (fop.vs(), fop.sent_len()),
        (1, 1),
        "BD frames take no N(S) and wait for nothing"
    );
}

/// A packet inside robot 1's TC frame that carries robot 2's APID is refused (counted in the
/// frame's result), never handed to either robot's queue: a frame's spacecraft ID and its
/// packets' APIDs must agree. The frame itself is FARM-1's to accept.
// req: 232.0-B-4/TC-34, 232.0-B-4/TC-35
#[test]
fn a_packet_for_another_robot_inside_a_frame_is_refused() {
    let two = BoardNumber::new(2).unwrap();
    let mut g: FrameGateway<2, 4, 8, 1024> = FrameGateway::new(FrameConfig::default());
    assert!(g.add(BoardNumber::ONE) && g.add(two));
    let v = g.tc_frame(0, &ping_frame(0x101, 0x102));
    assert_eq!(
        (v.robot, v.accepted, v.refused),
        (Some(BoardNumber::ONE), 0, 1)
    );
    assert!(v.verdict.is_ok(), "{:?}", v.verdict);
    assert_eq!(g.farm(BoardNumber::ONE).unwrap().vr(), 1);
    assert_eq!(
        g.farm(two).unwrap().vr(),
        0,
        "robot 2's channel saw nothing"
    );
}
