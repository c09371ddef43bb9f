package org.mmic.yamcs;

import java.io.BufferedReader;
import java.io.InputStreamReader;
import java.io.PrintStream;
import java.nio.charset.StandardCharsets;
import java.util.HashMap;
import java.util.HexFormat;
import java.util.Map;

import org.yamcs.ConfigurationException;
import org.yamcs.YConfiguration;
import org.yamcs.security.sdls.SdlsSecurityAssociation;

/**
 * The plug-in's SA outside YAMCS, made by its factory exactly as a link makes it, for the tests
 * (ground/tests/test_sdls_state.py): each run of this program is one "start" of the SA on its state file, and killing
 * it is a crash.
 *
 * <pre>
 * open KEY STATE SPI [rx]            make the SA; prints "ok" or "refused: &lt;the ConfigurationException&gt;"
 * tx KEY STATE SPI BLOCK N           protect N AD frames (SCID 257, VC 0, MAP 0, 4 data octets, FECF left 0) with the
 *                                    plan's mask; prints each frame in hex once applySecurity returned, flushed
 * rx KEY STATE SPI BLOCK WINDOW      reads 256-octet TM frames in hex from stdin, one per line; prints per frame
 *                                    "&lt;VerificationStatusCode&gt; &lt;the SA's last accepted IV&gt;"
 * </pre>
 *
 * Nothing here prints a key.
 */
public final class SdlsCounterTool {
    private static final byte[] MASK = HexFormat.of().parseHex("ffffffffffffffff000000000000000000000000");

    private SdlsCounterTool() {
    }

    private static SdlsSecurityAssociation make(String key, String state, int spi, int block, Integer window) {
        Map<String, Object> m = new HashMap<>();
        m.put("keyFile", key);
        m.put("stateFile", state);
        m.put("reserveBlock", block);
        if (window != null) {
            m.put("verifySeqNum", true);
            m.put("seqNumWindow", window);
        }
        return new ReprotectingAes256Gcm128Factory().create("tool", "tool", (short) spi, YConfiguration.wrap(m));
    }

    public static void main(String[] a) throws Exception {
        PrintStream out = new PrintStream(System.out, true, StandardCharsets.US_ASCII);
        HexFormat hex = HexFormat.of();
        switch (a[0]) {
        case "open" -> {
            try {
                make(a[1], a[2], Integer.parseInt(a[3]), 64, a.length > 4 ? 100000 : null);
                out.println("ok");
            } catch (ConfigurationException e) {
                out.println("refused: " + e.getMessage());
            }
        }
        case "tx" -> {
            SdlsSecurityAssociation sa = make(a[1], a[2], Integer.parseInt(a[3]), Integer.parseInt(a[4]), null);
            long n = Long.parseLong(a[5]);
            for (long i = 0; i < n; i++) {
                int len = 5 + 1 + 14 + 4 + 16 + 2;
                byte[] f = new byte[len];
                f[0] = 0x01; // version 0, AD, SCID 257 (0x101)
                f[1] = 0x01;
                f[2] = (byte) ((len - 1) >> 8);
                f[3] = (byte) (len - 1);
                f[4] = (byte) i;
                f[5] = (byte) 0xC0;
                f[20] = (byte) (i >> 24);
                f[21] = (byte) (i >> 16);
                f[22] = (byte) (i >> 8);
                f[23] = (byte) i;
                sa.applySecurity(f, 0, 6, len - 2, MASK);
                out.println(hex.formatHex(f));
            }
        }
        case "rx" -> {
            SdlsSecurityAssociation sa = make(a[1], a[2], Integer.parseInt(a[3]), Integer.parseInt(a[4]),
                    Integer.parseInt(a[5]));
            BufferedReader in = new BufferedReader(new InputStreamReader(System.in, StandardCharsets.US_ASCII));
            String line;
            while ((line = in.readLine()) != null) {
                if (line.isBlank()) {
                    continue;
                }
                byte[] f = hex.parseHex(line.trim());
                var status = sa.processSecurity(f, 0, 6, f.length - 6, MASK);
                out.println(status + " " + new java.math.BigInteger(1, sa.getSeqNum()));
            }
        }
        default -> throw new IllegalArgumentException("open | tx | rx");
        }
    }
}
