package org.mmic.yamcs;

import java.security.GeneralSecurityException;
import java.util.Arrays;

import javax.crypto.Cipher;
import javax.crypto.spec.GCMParameterSpec;
import javax.crypto.spec.SecretKeySpec;

import org.yamcs.security.sdls.SdlsSecurityAssociation;

/**
 * An AES-256-GCM security association (YAMCS 5.12.8's, with the plug-in's durable counter) with one change: a frame that is protected already is first
 * restored to its plaintext, then protected again under a fresh IV.
 * <p>
 * Why: on a COP-1 retransmission, {@code Cop1TcPacketHandler.getFrame()} calls {@code TcFrameFactory.encodeFrame} again
 * on the same {@code TcTransferFrame}, whose buffer {@code applySecurity} encrypted in place the first time. The
 * built-in SA then encrypts the first ciphertext under the next IV: the MAC verifies on board but the plaintext is
 * the first transmission's ciphertext (ground/repro_cop1_sdls.py, ground/README.md).
 * <p>
 * How a protected frame is recognised: {@code TcFrameFactory.makeFrame} allocates a zeroed buffer, so a frame not yet
 * protected has SPI 0 in its security header; a protected one has this SA's SPI there (SPI 0 must not be used). Its
 * old IV is read from the header and the frame is verified and decrypted with the key (the current one, else the one
 * before the last key change), the AAD computed with the same mask as when it was protected (encodeFrame rewrites
 * the same header first). A frame that does not verify is refused (GeneralSecurityException): no garbage goes out.
 * The old IV is never used again: the inner SA's counter moves on (the factory's inner SA is
 * {@link DurableAes256Gcm128}: YAMCS's SA with its counter under a durable reservation).
 */
public class ReprotectingAes256Gcm128 implements SdlsSecurityAssociation {
    private static final int IV_LEN = 12;
    private static final int TAG_BITS = 128;

    private final SdlsSecurityAssociation inner;
    private final int spi;
    private SecretKeySpec key;
    private SecretKeySpec previousKey;

    public ReprotectingAes256Gcm128(SdlsSecurityAssociation inner, short spi, byte[] key) {
        this.inner = inner;
        this.spi = spi & 0xFFFF;
        this.key = new SecretKeySpec(key, "AES");
    }

    @Override
    public void applySecurity(byte[] buffer, int frameStart, int secHeaderStart, int secTrailerEnd, byte[] authMask)
            throws GeneralSecurityException {
        int spiField = ((buffer[secHeaderStart] & 0xFF) << 8) | (buffer[secHeaderStart + 1] & 0xFF);
        if (spiField == spi && spi != 0) {
            restorePlaintext(buffer, frameStart, secHeaderStart, secTrailerEnd, authMask);
        }
        inner.applySecurity(buffer, frameStart, secHeaderStart, secTrailerEnd, authMask);
    }

    private void restorePlaintext(byte[] buffer, int frameStart, int secHeaderStart, int secTrailerEnd,
            byte[] authMask) throws GeneralSecurityException {
        byte[] iv = Arrays.copyOfRange(buffer, secHeaderStart + 2, secHeaderStart + 2 + IV_LEN);
        byte[] aad = new byte[authMask.length];
        for (int i = 0; i < authMask.length; i++) {
            aad[i] = (byte) (buffer[frameStart + i] & authMask[i]);
        }
        int dataStart = secHeaderStart + getHeaderSize();
        byte[] plaintext;
        try {
            plaintext = decrypt(key, iv, aad, buffer, dataStart, secTrailerEnd - dataStart);
        } catch (GeneralSecurityException e) {
            if (previousKey == null) {
                throw new GeneralSecurityException("retransmitted frame does not verify under its old IV", e);
            }
            plaintext = decrypt(previousKey, iv, aad, buffer, dataStart, secTrailerEnd - dataStart);
        }
        System.arraycopy(plaintext, 0, buffer, dataStart, plaintext.length);
        // back to the state TcFrameFactory.makeFrame leaves: security header and trailer zeroed
        Arrays.fill(buffer, secHeaderStart, dataStart, (byte) 0);
        Arrays.fill(buffer, secTrailerEnd - getTrailerSize(), secTrailerEnd, (byte) 0);
    }

    private static byte[] decrypt(SecretKeySpec k, byte[] iv, byte[] aad, byte[] buffer, int offset, int length)
            throws GeneralSecurityException {
        Cipher cipher = Cipher.getInstance("AES/GCM/NoPadding");
        cipher.init(Cipher.DECRYPT_MODE, k, new GCMParameterSpec(TAG_BITS, iv));
        cipher.updateAAD(aad);
        return cipher.doFinal(buffer, offset, length);
    }

    @Override
    public VerificationStatusCode processSecurity(byte[] buffer, int frameStart, int secHeaderStart,
            int secTrailerEnd, byte[] authMask) {
        return inner.processSecurity(buffer, frameStart, secHeaderStart, secTrailerEnd, authMask);
    }

    @Override
    public void setSecretKey(byte[] secretKey) {
        inner.setSecretKey(secretKey); // first: it may refuse (the durable state not tied to the new key)
        previousKey = key;
        key = new SecretKeySpec(secretKey, "AES");
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
        return inner.getAlgorithm() + " (re-protecting)";
    }

    @Override
    public void skipVerifyingNextSeqNum() {
        inner.skipVerifyingNextSeqNum();
    }

    @Override
    public byte[] getSeqNum() {
        return inner.getSeqNum();
    }

    @Override
    public void setSeqNum(byte[] newSeqNum) {
        inner.setSeqNum(newSeqNum);
    }

    @Override
    public byte[] securityHdrAuthMask() {
        return inner.securityHdrAuthMask();
    }
}
