package org.mmic.yamcs;

import java.io.IOException;
import java.math.BigInteger;
import java.security.GeneralSecurityException;
import java.util.Arrays;

import org.slf4j.Logger;
import org.slf4j.LoggerFactory;
import org.yamcs.ConfigurationException;
import org.yamcs.security.sdls.SdlsSecurityAssociation;
import org.yamcs.security.sdls.SecurityAssociationAes256Gcm128;

/**
 * YAMCS 5.12.8's AES-256-GCM security association with its counter under a durable reservation
 * ({@link SdlsCounterState}, the library's scheme, {@code src/link/sdls/counter.rs}) instead of YAMCS's memento
 * database, so that no IV is used twice and no frame accepted twice across restarts of YAMCS, a SIGKILL at any instant
 * or the loss of YAMCS's data directory included.
 *
 * <p>
 * The cryptography and the window are YAMCS's own SA ({@link SecurityAssociationAes256Gcm128}, made without an instance
 * name so that it keeps nothing in the memento database, and with the stored counter as its initial sequence number so
 * that it never skips the check of the first frame); this class only moves its counter:
 * <ul>
 * <li>sender (state role {@code tx}): an IV at or above the stored reservation is used only after the next reservation
 * ({@code reserveBlock} further) is written durably; after a restart it continues from the stored reservation, above
 * every IV it may have used. A write that fails fails the frame (it is not sent).
 * <li>receiver (role {@code rx}, {@code verifySeqNum: true} required): YAMCS's check (MAC, then the IV within
 * {@code seqNumWindow} ahead of the last accepted), then, for an IV beyond the stored floor, the next floor (that IV +
 * {@code reserveBlock}) is written durably before the frame is accepted; after a restart the stored floor is the last
 * accepted IV, so every frame accepted before is a replay. A write that fails refuses the frame.
 * </ul>
 * YAMCS's {@code skipVerifyingNextSeqNum} is refused, and the HTTP API may move a counter only forwards.
 */
public class DurableAes256Gcm128 implements SdlsSecurityAssociation {
    private static final Logger log = LoggerFactory.getLogger(DurableAes256Gcm128.class);
    private static final int IV_LEN = 12;
    private static final BigInteger SPACE = SdlsCounterState.IV_SPACE;
    private static final BigInteger HALF = SPACE.shiftRight(1);

    private final SecurityAssociationAes256Gcm128 inner;
    private final SdlsCounterState state;
    private final String name;
    private final int spi;
    private final BigInteger block;
    /** tx: the IV of the next frame (2^96 when all are spent); rx: the last IV accepted. */
    private BigInteger counter;
    /** tx: IVs below it may be used; rx: IVs up to it (mod 2^96, ahead of counter) may be accepted. */
    private BigInteger durable;

    public DurableAes256Gcm128(String linkName, short spi, byte[] key, SdlsCounterState state, int seqNumWindow,
            boolean verifySeqNum, int reserveBlock) {
        this.spi = spi & 0xFFFF;
        this.name = "SDLS SA " + this.spi + " (" + linkName + ", " + state.file() + ")";
        if (reserveBlock < 1) {
            throw new ConfigurationException(name + ": reserveBlock must be at least 1");
        }
        if (state.role() == SdlsCounterState.Role.RX && !verifySeqNum) {
            throw new ConfigurationException(name + ": a receiver's state needs verifySeqNum: true (without it any"
                    + " replay is accepted)");
        }
        if (state.role() == SdlsCounterState.Role.TX && verifySeqNum) {
            throw new ConfigurationException(name + ": a sender's state (role tx) with verifySeqNum: true: is this"
                    + " the receiver's (TM) SA? Its state file must be provisioned with --role rx");
        }
        if (seqNumWindow < 1) {
            throw new ConfigurationException(name + ": seqNumWindow must be at least 1");
        }
        this.state = state;
        this.block = BigInteger.valueOf(reserveBlock);
        this.durable = state.value();
        this.counter = durable;
        // no instance name: YAMCS's SA keeps nothing in the memento database; an initial sequence number: it never
        // skips verifying the first frame
        this.inner = new SecurityAssociationAes256Gcm128(null, null, key, spi, ivBytes(counter), seqNumWindow,
                verifySeqNum);
        if (state.role() == SdlsCounterState.Role.TX) {
            log.info("{}: sender, next IV {} (the stored reservation), reserved {} at a time", name, counter, block);
        } else {
            log.info("{}: receiver, last accepted IV {} (the stored floor{}), window {}, floor reserved {} ahead",
                    name, counter, counter.equals(SPACE.subtract(BigInteger.ONE)) ? ": nothing accepted yet" : "",
                    seqNumWindow, block);
        }
    }

    private static byte[] ivBytes(BigInteger v) {
        byte[] b = v.mod(SPACE).toByteArray();
        byte[] out = new byte[IV_LEN];
        int n = Math.min(b.length, IV_LEN);
        System.arraycopy(b, b.length - n, out, IV_LEN - n, n);
        return out;
    }

    private static BigInteger fromIv(byte[] buffer, int offset) {
        return new BigInteger(1, Arrays.copyOfRange(buffer, offset, offset + IV_LEN));
    }

    @Override
    public synchronized void applySecurity(byte[] buffer, int frameStart, int secHeaderStart, int secTrailerEnd,
            byte[] authMask) throws GeneralSecurityException {
        if (state.role() != SdlsCounterState.Role.TX) {
            throw new GeneralSecurityException(name + " is a receiver's state: it protects no frame");
        }
        if (counter.compareTo(SPACE) >= 0) {
            throw new GeneralSecurityException(name + ": every IV of the 96-bit counter is spent; a new key is needed");
        }
        if (counter.compareTo(durable) >= 0) {
            BigInteger next = counter.add(block).min(SPACE);
            try {
                state.store(next);
            } catch (IOException e) {
                log.warn("{}: the next reservation ({}) could not be written, the frame is not sent: {}", name, next,
                        e.toString());
                throw new GeneralSecurityException(name + ": the IV reservation could not be written", e);
            }
            durable = next;
            log.debug("{}: reserved IVs below {}", name, next);
        }
        inner.setSeqNum(ivBytes(counter)); // the one the frame gets
        try {
            inner.applySecurity(buffer, frameStart, secHeaderStart, secTrailerEnd, authMask);
        } finally {
            counter = counter.add(BigInteger.ONE); // spent even if protecting failed half-way
        }
    }

    @Override
    public synchronized VerificationStatusCode processSecurity(byte[] buffer, int frameStart, int secHeaderStart,
            int secTrailerEnd, byte[] authMask) {
        if (state.role() != SdlsCounterState.Role.RX) {
            log.warn("{} is a sender's state: it accepts no frame", name);
            return VerificationStatusCode.InvalidSPI;
        }
        BigInteger iv = fromIv(buffer, secHeaderStart + 2); // before YAMCS's SA zeroes the header
        inner.setSeqNum(ivBytes(counter));
        VerificationStatusCode status = inner.processSecurity(buffer, frameStart, secHeaderStart, secTrailerEnd,
                authMask);
        if (status != VerificationStatusCode.NoFailure) {
            return status;
        }
        // MAC verified, IV within the window ahead of the last accepted one
        BigInteger d = iv.subtract(counter).mod(SPACE);
        BigInteger ahead = durable.subtract(counter).mod(SPACE);
        if (d.compareTo(ahead) > 0) {
            BigInteger floor = iv.add(block).mod(SPACE);
            try {
                state.store(floor);
            } catch (IOException e) {
                inner.setSeqNum(ivBytes(counter));
                log.warn("{}: the next floor ({}) could not be written, frame with IV {} refused: {}", name, floor, iv,
                        e.toString());
                return VerificationStatusCode.AntiReplaySequenceNumberFailure;
            }
            durable = floor;
        }
        counter = iv;
        return VerificationStatusCode.NoFailure;
    }

    @Override
    public void skipVerifyingNextSeqNum() {
        log.warn("{}: not skipping the check of the next frame's sequence number (it would accept a replay)", name);
    }

    @Override
    public synchronized byte[] getSeqNum() {
        return ivBytes(counter.min(SPACE.subtract(BigInteger.ONE)));
    }

    /** YAMCS's HTTP API ({@code PUT /api/sdls/{instance}/{link}/{spi}/seq}): only forwards. */
    @Override
    public synchronized void setSeqNum(byte[] newSeqNum) {
        BigInteger n = new BigInteger(1, newSeqNum).mod(SPACE);
        if (state.role() == SdlsCounterState.Role.TX) {
            if (n.compareTo(counter) < 0) {
                throw new IllegalArgumentException(name + ": the next IV cannot go back from " + counter + " to " + n
                        + " (IVs would be used twice)");
            }
            if (n.compareTo(durable) >= 0) {
                store(n.add(block).min(SPACE));
            }
        } else {
            BigInteger d = n.subtract(counter).mod(SPACE);
            if (d.compareTo(HALF) >= 0) {
                throw new IllegalArgumentException(name + ": the last accepted IV cannot go back from " + counter
                        + " to " + n + " (frames accepted before would be accepted again)");
            }
            if (d.compareTo(durable.subtract(counter).mod(SPACE)) > 0) {
                store(n.add(block).mod(SPACE));
            }
        }
        counter = n;
        inner.setSeqNum(ivBytes(n));
        log.info("{}: counter set to {} through the API", name, n);
    }

    private void store(BigInteger v) {
        try {
            state.store(v);
            durable = v;
        } catch (IOException e) {
            throw new IllegalStateException(name + ": the counter could not be written: " + e, e);
        }
    }

    @Override
    public synchronized void setSecretKey(byte[] secretKey) {
        try {
            state.rekey(secretKey);
        } catch (IOException e) {
            throw new IllegalStateException(name + ": the state file could not be tied to the new key: " + e, e);
        }
        inner.setSecretKey(secretKey);
    }

    @Override
    public int getHeaderSize() {
        return inner.getHeaderSize();
    }

    @Override
    public int getTrailerSize() {
        return inner.getTrailerSize();
    }

    @Override
    public int getKeyLenBits() {
        return inner.getKeyLenBits();
    }

    @Override
    public String getAlgorithm() {
        return inner.getAlgorithm();
    }

    @Override
    public byte[] securityHdrAuthMask() {
        return inner.securityHdrAuthMask();
    }
}
